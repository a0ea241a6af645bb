"""Event and status callbacks: they run on the client's thread, with the GIL,
may call into the client, and end with their Subscription."""

import sys
import threading

import pytest

import dh3
from conftest import DEADLINE, spec


class Log:
    """What callbacks saw, and on which thread; wait() for a condition on it."""

    def __init__(self):
        self.items = []
        self.threads = set()
        self.changed = threading.Condition()

    def add(self, item):
        with self.changed:
            self.items.append(item)
            self.threads.add(threading.get_ident())
            self.changed.notify_all()

    def wait(self, condition, timeout=DEADLINE):
        with self.changed:
            return self.changed.wait_for(lambda: condition(self.items), timeout)


def kinds(items):
    return [e.kind for e in items]


def test_hand_events_reach_the_callback_on_the_clients_thread(client):
    one = client.wait_for_hand(spec(1), timeout=DEADLINE)
    log = Log()
    subscription = one.subscribe(log.add)
    assert subscription.active()
    assert one.initialize().ok
    assert log.wait(lambda items: dh3.EventKind.INITIALIZED in kinds(items)), kinds(log.items)
    assert one.grasp(40).ok
    assert log.wait(lambda items: dh3.EventKind.GRASPED in kinds(items)), kinds(log.items)
    assert all(e.hand == one.address for e in log.items)
    assert all(isinstance(e.kind, dh3.EventKind) for e in log.items)
    # What the value is, by name: GRASPED's is the force it holds with.
    grasped = next(e for e in log.items if e.kind == dh3.EventKind.GRASPED)
    assert grasped.named_value == ("closing_force", grasped.value), grasped.named_value
    initialized = next(e for e in log.items if e.kind == dh3.EventKind.INITIALIZED)
    assert initialized.named_value is None
    assert threading.get_ident() not in log.threads
    assert len(log.threads) == 1
    subscription.unsubscribe()
    assert not subscription.active()
    seen = len(log.items)
    assert one.release(100).ok
    assert one.initialize().ok  # would send INITIALIZED again
    # Another subscription sees the next event; the ended one never does.
    later = Log()
    with one.subscribe(later.add):
        assert one.grasp(40).ok
        assert later.wait(lambda items: dh3.EventKind.GRASPED in kinds(items))
    assert len(log.items) == seen


def test_client_wide_and_filtered_subscriptions(client):
    two = client.wait_for_hand(spec(2), timeout=DEADLINE)
    three = client.wait_for_hand(spec(3), timeout=DEADLINE)
    everything, only_three, statuses = Log(), Log(), Log()
    subscriptions = [
        client.subscribe(everything.add),
        client.subscribe(only_three.add, only=three.address),
        client.subscribe_status(statuses.add, only=two.address),
    ]
    assert two.initialize().ok and three.initialize().ok
    assert two.grasp(30).grasp == dh3.GraspOutcome.MISSED
    assert three.grasp(30).grasp == dh3.GraspOutcome.MISSED
    hands_missed = lambda items: {e.hand.can_id for e in items if e.kind == dh3.EventKind.MISSED}
    assert everything.wait(lambda items: {2, 3} <= hands_missed(items))
    assert only_three.wait(lambda items: 3 in hands_missed(items))
    assert {e.hand.can_id for e in only_three.items} == {3}
    assert statuses.wait(lambda items: any(s.grip == dh3.GripState.MISSED for s in items))
    assert {s.address.can_id for s in statuses.items} == {2}
    for subscription in subscriptions:
        subscription.unsubscribe()


def test_a_callback_may_call_the_client_and_unsubscribe_itself(client):
    two = client.wait_for_hand(spec(2), timeout=DEADLINE)
    answers = Log()
    holder = {}

    def on_status(status):
        # A blocking call from the client's own thread, then the end of this
        # subscription from inside its callback.
        answers.add(two.read(dh3.reg.position).code)
        holder["subscription"].unsubscribe()

    holder["subscription"] = client.subscribe_status(on_status, only=two.address)
    assert answers.wait(lambda items: len(items) >= 1)
    assert answers.items[0] == dh3.Code.OK
    assert two.move_to(40).ok and two.move_to(60).ok
    assert two.wait_until(lambda s: s.target_position == 60, timeout=DEADLINE)
    assert not holder["subscription"].active()
    assert len(answers.items) == 1


def test_an_exception_in_a_callback_is_reported_and_later_callbacks_still_run(client,
                                                                              monkeypatch):
    three = client.wait_for_hand(spec(3), timeout=DEADLINE)
    unraisable = Log()
    monkeypatch.setattr(sys, "unraisablehook", unraisable.add)
    calls = Log()

    def failing(event):
        calls.add(event)
        raise RuntimeError("callback failed")

    with three.subscribe(failing):
        assert three.initialize().ok
        assert three.move_to(70).ok
        assert three.grasp(30).ok
        assert calls.wait(lambda items: len(items) >= 2), kinds(calls.items)
    assert unraisable.wait(lambda items: len(items) >= 2)
    assert isinstance(unraisable.items[0].exc_value, RuntimeError)


def test_future_callbacks_run_when_the_reply_comes(client):
    two = client.wait_for_hand(spec(2), timeout=DEADLINE)
    done = Log()
    future = two.release_async(100)
    future.add_done_callback(lambda f: done.add(f.result()))
    assert done.wait(lambda items: len(items) == 1)
    assert done.items[0].ok, done.items[0]


def test_futures_complete_on_the_clients_callback_thread(client):
    """A Future is completed on the thread that runs the event and status
    callbacks, after those before it; its done callbacks run there and may make
    blocking calls."""
    two = client.wait_for_hand(spec(2), timeout=DEADLINE)
    release = threading.Event()
    statuses = Log()
    done = Log()

    def on_status(status):
        statuses.add(status)
        release.wait(DEADLINE)  # holds the callback thread until the test is ready

    with client.subscribe_status(on_status, only=two.address):
        assert statuses.wait(lambda items: len(items) >= 1)
        futures = [two.read_async(dh3.reg.position) for _ in range(3)]
        futures.append(client.group_async(dh3.GroupCommand.INITIALIZE, [two.address]))
        # Whatever came back waits behind the status callback that holds the
        # thread: no thread of its own completes a Future.
        assert not any(f.done() for f in futures)
        futures[0].add_done_callback(
            lambda f: done.add((f.result().code, two.read(dh3.reg.position).code)))
        release.set()
        group = futures[-1].result(timeout=DEADLINE)
        assert group.ok, group.message
        assert all(f.result(timeout=DEADLINE).ok for f in futures[:-1])
        assert done.wait(lambda items: len(items) == 1)
    assert done.items[0] == (dh3.Code.OK, dh3.Code.OK)
    assert done.threads == statuses.threads
