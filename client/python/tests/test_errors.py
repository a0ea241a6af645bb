"""The errors a script meets: invalid arguments, unknown hands, missing
services, timeouts (the client's and the service's)."""

import pytest

import dh3
from conftest import DEADLINE, DOMAIN, SERVICE, Service, sim_config, spec

SLOW = f"{SERVICE}slow"


@pytest.fixture(scope="module")
def slow_service():
    """Fingers move 1 % a second here, but the service waits 0.3 s for a motion
    to end: a long move ends with the service's TIMEOUT."""
    config = sim_config(position_speed=1).replace(
        "    init_timeout_ms:", "    motion_timeout_ms: 300\n    init_timeout_ms:")
    running = Service(config, name=SLOW)
    yield running
    assert running.stop() == 0


def test_invalid_arguments(hand):
    for reply in (hand.move_to(150), hand.rotate_to(-1), hand.set_force(5),
                  hand.set_force(50, 101), hand.grasp(0), hand.read(0x7777)):
        assert reply.code == dh3.Code.INVALID_ARGUMENT, reply
        assert reply.message, reply
        assert not reply and not reply.ok


def test_motion_before_initialization(client, slow_service):
    three = client.wait_for_hand(spec(3, service=SLOW), timeout=DEADLINE)
    early = three.move_to(50)
    assert early.code == dh3.Code.NOT_INITIALIZED, early
    assert "not initialized" in early.message


def test_unknown_hand(client, service):
    client.wait_for_service(SERVICE, timeout=DEADLINE)
    unknown = client.hand(dh3.HandAddress(SERVICE, "bus0", 9)).initialize()
    assert unknown.code == dh3.Code.UNKNOWN_HAND
    assert "no hand 9" in unknown.message
    bad_bus = client.hand(dh3.HandAddress(SERVICE, "nobus", 1)).stop()
    assert bad_bus.code == dh3.Code.UNKNOWN_HAND
    assert "no bus 'nobus'" in bad_bus.message
    # The service's own list of its hands answers, not the end of the (long) wait.
    with pytest.raises(dh3.Error) as error:
        client.wait_for_hand(spec(9), timeout=300.0)
    assert error.value.code == dh3.Code.UNKNOWN_HAND
    assert "no hand bus0/9" in error.value.message
    assert spec(1) in error.value.message, error.value.message
    with pytest.raises(dh3.Error) as error:
        client.find_hand("bus0/9")
    assert error.value.code == dh3.Code.UNKNOWN_HAND


def test_bad_and_ambiguous_specs_are_invalid_arguments(client, service, slow_service):
    client.wait_for_hand(spec(1), timeout=DEADLINE)
    client.wait_for_hand(spec(1, service=SLOW), timeout=DEADLINE)
    # "bus0/1": hand 1 of both services.
    for text in ("a/b/c/d", "", "bus0/1"):
        with pytest.raises(dh3.Error) as error:
            client.wait_for_hand(text, timeout=DEADLINE)
        assert error.value.code == dh3.Code.INVALID_ARGUMENT, text


def test_missing_service(client):
    with pytest.raises(dh3.Error) as error:
        client.wait_for_hand(spec(1, service="nobody-here"), timeout=0.5)
    assert error.value.code == dh3.Code.NO_SERVICE
    assert "500 ms" in error.value.message, error.value.message
    with pytest.raises(dh3.Error) as error:
        client.wait_for_service("nobody-here", timeout=0.5)
    assert error.value.code == dh3.Code.NO_SERVICE
    lost = client.hand(dh3.HandAddress("nobody-here", "bus0", 1)).move_to(10, timeout=0.5)
    assert lost.code == dh3.Code.NO_SERVICE


def test_timeouts(client, slow_service):
    one = client.wait_for_hand(spec(2, service=SLOW), timeout=DEADLINE)
    assert one.initialize().ok
    # The service's: the fingers did not arrive in its time.
    service_timeout = one.grasp(20, timeout=DEADLINE)
    assert service_timeout.code == dh3.Code.TIMEOUT, service_timeout
    # The client's own deadline: no reply in time.
    no_reply = one.release(100, timeout=0.05)
    assert no_reply.code == dh3.Code.NO_REPLY, no_reply
    assert "within 50 ms" in no_reply.message, no_reply
    # A wait that is not met ends with None.
    assert one.wait_until(lambda s: s.position == 12345, timeout=0.3) is None


def test_a_raising_predicate_raises_from_wait_until(hand):
    def predicate(status):
        raise RuntimeError("from the predicate")

    with pytest.raises(RuntimeError, match="from the predicate"):
        hand.wait_until(predicate, timeout=DEADLINE)


def test_follow_one_service_or_refuse_a_malformed_one(service, slow_service):
    """follow=: only that service's hands reach the client; a malformed one
    leaves the client unconnected, saying why."""
    with dh3.Client(domain=DOMAIN, default_timeout=DEADLINE, follow=SLOW) as follower:
        assert follower.connected(), follower.error()
        follower.wait_for_service(SLOW, timeout=DEADLINE)
        assert follower.wait_for_statuses(timeout=DEADLINE)
        assert {s.address.service for s in follower.hands()} == {SLOW}
        assert [s.name for s in follower.services()] == [SLOW]
        assert follower.watch_traffic().statuses > 0
    bad = dh3.Client(domain=DOMAIN, follow="cell/bus0/3")
    assert not bad.connected()
    assert "cannot follow 'cell/bus0/3'" in bad.error(), bad.error()
