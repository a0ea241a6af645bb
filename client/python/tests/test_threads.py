"""Blocking calls release the GIL: other Python threads run while one waits."""

import threading

import pytest

import dh3
from conftest import DEADLINE, SERVICE, Service, sim_config, spec

SLOW = f"{SERVICE}slow"


@pytest.fixture(scope="module")
def slow_service():
    """Fingers move 2 % a second: a grasp on nothing takes most of a minute."""
    running = Service(sim_config(position_speed=2), name=SLOW)
    yield running
    assert running.stop() == 0


def test_two_threads_drive_two_hands_at_once(client):
    failures = []
    barrier = threading.Barrier(2)

    def drive(can_id, low, high):
        hand = client.wait_for_hand(spec(can_id), timeout=DEADLINE)
        barrier.wait()
        if not hand.initialize().ok:
            failures.append((can_id, "initialize"))
        for _ in range(5):
            for position in (low, high):
                reply = hand.move_to(position)
                if not reply.ok:
                    failures.append((can_id, reply))
        grasp = hand.grasp(30)
        if grasp.grasp != dh3.GraspOutcome.MISSED:
            failures.append((can_id, grasp))
        if not hand.release(high).ok:
            failures.append((can_id, "release"))

    threads = [threading.Thread(target=drive, args=(2, 20, 80)),
               threading.Thread(target=drive, args=(3, 10, 90))]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
        assert not t.is_alive()
    assert failures == []
    assert client.find_hand(spec(2)).wait_until(lambda s: s.position == 80, timeout=DEADLINE)
    assert client.find_hand(spec(3)).wait_until(lambda s: s.position == 90, timeout=DEADLINE)


def test_another_thread_runs_while_one_waits_in_a_blocking_grasp(client, slow_service):
    """The worker runs Python (counting, reading the status) while the main
    thread is inside grasp(); it then stops the hand, which ends that grasp
    CANCELLED. Had grasp() kept the GIL, the worker could not run until the
    grasp ended on its own (MISSED, the fingers closed on nothing)."""
    two = client.wait_for_hand(spec(2, service=SLOW), timeout=DEADLINE)
    assert two.initialize().ok
    assert two.wait_until(lambda s: s.position == 100, timeout=DEADLINE)
    grasping = threading.Event()
    worker_saw = {}

    def worker():
        grasping.wait(timeout=DEADLINE)
        counted = 0
        while counted < 100000:
            counted += 1
        # The grasp under way (its position is not read while the fingers move).
        moving = two.wait_until(
            lambda s: s.grip == dh3.GripState.MOVING and s.target_position == 0,
            timeout=DEADLINE)
        worker_saw["counted"] = counted
        worker_saw["moving"] = moving
        worker_saw["stop"] = two.stop()

    thread = threading.Thread(target=worker)
    thread.start()
    grasping.set()
    grasp = two.grasp(20, timeout=120)
    thread.join(timeout=DEADLINE)
    assert worker_saw.get("counted") == 100000
    assert worker_saw["moving"] is not None
    assert worker_saw["stop"].ok, worker_saw["stop"]
    assert grasp.code == dh3.Code.CANCELLED, grasp
