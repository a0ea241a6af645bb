"""Every command against dh3-service on a simulated bus of three hands."""

import concurrent.futures
import socket

import pytest

import dh3
from conftest import DEADLINE, DOMAIN, SERVICE, Service, sim_config, spec


def test_lookups(client):
    info = client.wait_for_service(SERVICE, timeout=DEADLINE)
    assert info.name == SERVICE and info.ready
    assert [b.name for b in info.buses] == ["bus0"]
    assert [h.can_id for h in info.buses[0].hands] == [1, 2, 3]
    assert client.wait_for_statuses(timeout=DEADLINE)
    assert SERVICE in [s.name for s in client.services()]
    assert client.service(SERVICE).name == SERVICE
    assert client.service("nobody-here") is None
    hand = client.wait_for_hand(spec(3), timeout=DEADLINE)
    assert hand.address == dh3.HandAddress(SERVICE, "bus0", 3)
    mine = sorted(s.address.can_id for s in client.hands() if s.address.service == SERVICE)
    assert mine == [1, 2, 3]
    assert client.status(hand.address).address == hand.address
    assert client.find_hand(spec(2)).address.can_id == 2
    assert hand.wait_until(lambda s: s.online, timeout=DEADLINE) is not None
    assert hand.online()
    assert hand.status().firmware_version_text == "4.1.2.0"


def test_status_says_when_its_values_were_read(client):
    hand = client.wait_for_hand(spec(3), timeout=DEADLINE)
    # Online comes with the firmware read; the position is read in a later frame.
    first = hand.wait_until(lambda s: s.online and s.position is not None and s.read_at_ns > 0,
                            timeout=DEADLINE)
    assert first is not None, hand.status()
    # At rest nothing changes, yet the hand is read again: a later sample says so.
    later = hand.wait_until(lambda s: s.read_at_ns > first.read_at_ns, timeout=DEADLINE)
    assert later is not None, hand.status()
    assert later.position == first.position, (first, later)


def test_values_not_read_are_none_and_numbers_once_read(client):
    """Hand 9 is configured but not on the bus: it never answers."""
    name = f"{SERVICE}unread"
    config = sim_config(ids=(1,)).replace("spec: sim\n", "spec: sim:1\n") + "      - {id: 9}\n"
    running = Service(config, name=name)
    try:
        never = client.wait_for_hand(spec(9, name), timeout=DEADLINE)
        unread = never.wait_until(lambda s: s.last_error == dh3.Code.TIMEOUT, timeout=DEADLINE)
        assert unread is not None and not unread.online, never.status()
        for value in ("position", "target_position", "closing_force", "opening_force",
                      "rotation", "rotation_target"):
            assert getattr(unread, value) is None, (value, unread)
        assert "position=None" in repr(unread)

        one = client.wait_for_hand(spec(1, name), timeout=DEADLINE)
        read = one.wait_until(lambda s: s.online and s.position is not None, timeout=DEADLINE)
        assert read is not None, one.status()
        assert read.position == 100 and read.closing_force == 50 and read.rotation == 0, read
        assert read.target_position is None  # never written
        assert one.initialize().ok
        assert one.move_to(30).ok
        assert one.status().target_position == 30
    finally:
        assert running.stop() == 0


def test_command_traffic_counts_this_clients_requests_and_replies(client):
    hand = client.wait_for_hand(spec(3), timeout=DEADLINE)
    before = client.command_traffic()
    assert hand.read(dh3.reg.position).ok
    after = client.command_traffic()
    assert after.requests_written == before.requests_written + 1
    assert after.own_replies == before.own_replies + 1


def test_initialize_move_grasp_release(client):
    one = client.wait_for_hand(spec(1), timeout=DEADLINE)
    reply = one.initialize()
    assert reply.ok and reply and reply.code == dh3.Code.OK, reply
    assert one.wait_until(lambda s: s.initialized, timeout=DEADLINE)
    assert one.move_to(60).ok
    assert one.wait_until(lambda s: s.position == 60 and s.grip == dh3.GripState.ARRIVED,
                          timeout=DEADLINE), one.status()
    # Hand 1 has an object at 40: closing from 60 stops on it.
    grasp = one.grasp(40)
    assert grasp.ok, grasp
    assert grasp.grasp == dh3.GraspOutcome.GRASPED
    assert 35 <= grasp.value <= 45
    assert one.wait_until(lambda s: s.grip == dh3.GripState.GRASPED, timeout=DEADLINE)
    release = one.release(100)
    assert release.ok, release
    assert one.wait_until(lambda s: s.position == 100, timeout=DEADLINE)


def test_grasp_on_nothing_is_missed_at_position_zero(hand):
    grasp = hand.grasp(30)
    assert grasp.ok, grasp
    assert grasp.grasp == dh3.GraspOutcome.MISSED
    assert grasp.value == 0


def test_reads_rotates_sets_forces_and_stops(client):
    three = client.wait_for_hand(spec(3), timeout=DEADLINE)
    assert three.initialize().ok
    force = three.set_force(70, 30)
    assert force.ok, force
    assert three.wait_until(lambda s: s.closing_force == 70 and s.opening_force == 30,
                            timeout=DEADLINE)
    assert three.set_force(60).ok
    assert three.read(dh3.reg.closing_force).value == 60
    assert three.read(dh3.reg.firmware_version).value == 0x04010200
    assert three.rotate_to(50).ok
    assert three.wait_until(lambda s: s.rotation == 50, timeout=DEADLINE)
    assert three.stop().ok


def test_scans(client, hand):
    scan = client.scan(SERVICE, "bus0")
    assert scan.ok, scan
    assert scan.found_ids == [1, 2, 3]
    from_hand = hand.scan_bus()
    assert from_hand.ok, from_hand
    assert from_hand.found_ids == [1, 2, 3]


def test_asynchronous_forms_return_futures_of_replies(client, hand):
    futures = {
        "move_to": hand.move_to_async(50),
        "read": hand.read_async(dh3.reg.position),
        "rotate_to": hand.rotate_to_async(20),
        "set_force": hand.set_force_async(50, 40),
        "scan_bus": hand.scan_bus_async(),
        "scan": client.scan_async(SERVICE, "bus0"),
    }
    for name, future in futures.items():
        assert isinstance(future, concurrent.futures.Future), name
        reply = future.result(timeout=DEADLINE)
        assert isinstance(reply, dh3.Reply) and reply.ok, (name, reply)
    grasp = hand.grasp_async(30).result(timeout=DEADLINE)
    assert grasp.grasp == dh3.GraspOutcome.MISSED
    assert hand.release_async(100).result(timeout=DEADLINE).ok
    assert hand.stop_async().result(timeout=DEADLINE).ok
    assert hand.initialize_async().result(timeout=DEADLINE).ok
    done = []
    future = hand.read_async(dh3.reg.position)
    future.add_done_callback(lambda f: done.append(f.result().value))
    concurrent.futures.wait([future], timeout=DEADLINE)
    assert done == [future.result().value]


def test_a_lease_holder_keeps_other_clients_out(client, hand):
    holder = "dh3-client@" + socket.gethostname()  # the fixture's participant, as shown
    with dh3.Client(domain=DOMAIN, participant_name="other", default_timeout=DEADLINE) as other:
        other.wait_for_service(SERVICE, timeout=DEADLINE)
        theirs = other.hand(hand.address)
        lease = hand.acquire_lease(30.0)
        assert lease.ok, lease
        denied = theirs.move_to(10)
        assert denied.code == dh3.Code.DENIED
        assert denied.lease_holder == holder
        assert hand.renew_lease(30.0).ok
        assert hand.wait_until(lambda s: s.lease_holder == holder, timeout=DEADLINE)
        assert hand.move_to(30).ok
        assert hand.release_lease().ok
        allowed = theirs.move_to(10)
        assert allowed.ok, allowed
        assert theirs.acquire_lease_async(5.0).result(timeout=DEADLINE).ok
        assert theirs.renew_lease_async(5.0).result(timeout=DEADLINE).ok
        assert theirs.release_lease_async().result(timeout=DEADLINE).ok


def test_administrative_commands_are_denied_unless_allowed(hand):
    for reply in (hand.set_can_id(5), hand.set_baud_rate(2),
                  hand.set_can_id_async(5).result(timeout=DEADLINE),
                  hand.set_baud_rate_async(2).result(timeout=DEADLINE)):
        assert reply.code == dh3.Code.DENIED, reply
        assert "administrative" in reply.message or "--allow-admin" in reply.message


def test_group_grasp_reports_each_hand(client):
    hands = [dh3.HandAddress(SERVICE, "bus0", 1), dh3.HandAddress(SERVICE, "bus0", 3)]
    for address in hands:
        assert client.wait_for_hand(str(address), timeout=DEADLINE)
    init = client.group(dh3.GroupCommand.INITIALIZE, hands, timeout=DEADLINE)
    assert init.ok, init.message
    release = client.group(dh3.GroupCommand.RELEASE, hands, 100, timeout=DEADLINE)
    assert release.ok, release.message
    grasp = client.group(dh3.GroupCommand.GRASP, hands, 50, timeout=DEADLINE)
    assert grasp.ok, grasp.message
    assert [m.hand for m in grasp.hands] == hands
    assert grasp.hands[0].grasp == dh3.GraspOutcome.GRASPED
    assert grasp.hands[1].grasp == dh3.GraspOutcome.MISSED
    # A force out of range: refused before anything is sent, the hand named.
    refused = client.group(dh3.GroupCommand.GRASP, hands, 5, timeout=DEADLINE)
    assert refused.code == dh3.Code.INVALID_ARGUMENT
    assert str(hands[0]) in refused.message
