"""A service that dies and comes back: pending calls end SERVICE_LOST, its
hands go offline, and the same Hand objects work once it is back."""

import threading

import dh3
from conftest import DEADLINE, DOMAIN, SERVICE, Service, sim_config, spec


def test_killed_service_ends_pending_calls_and_the_same_hand_works_after_restart():
    service = Service(sim_config(init_time_ms=600000))
    restarted = None
    try:
        with dh3.Client(domain=DOMAIN, default_timeout=DEADLINE) as client:
            one = client.wait_for_hand(spec(1), timeout=DEADLINE)
            assert one.wait_until(lambda s: s.online, timeout=DEADLINE)
            events = []
            went_offline = threading.Event()

            def on_event(event):
                events.append(event)
                if event.kind == dh3.EventKind.OFFLINE:
                    went_offline.set()

            subscription = one.subscribe(on_event)
            pending = one.initialize_async(timeout=120)
            # Requests from one client arrive in order: once another hand's
            # read is answered, the service has the INITIALIZE (ten minutes).
            probe = client.hand(dh3.HandAddress(SERVICE, "bus0", 3)).read(dh3.reg.position)
            assert probe.ok, probe
            service.kill()

            lost = pending.result(timeout=60)
            assert lost.code == dh3.Code.SERVICE_LOST, lost
            assert "INITIALIZE" in lost.message
            status = one.wait_until(lambda s: not s.online, timeout=60)
            assert status is not None and status.service_lost
            assert not one.online()
            assert went_offline.wait(timeout=DEADLINE)
            offline = [e for e in events if e.kind == dh3.EventKind.OFFLINE]
            assert offline[0].from_client

            # While it is away a call waits (within its timeout) for it.
            away = one.read(dh3.reg.position, timeout=0.3)
            assert away.code in (dh3.Code.NO_SERVICE, dh3.Code.SERVICE_LOST), away

            restarted = Service(sim_config())
            back = one.wait_until(lambda s: s.online and not s.service_lost, timeout=60)
            assert back is not None
            again = one.initialize()
            assert again.ok, again
            assert one.wait_until(lambda s: s.online and s.initialized, timeout=DEADLINE)
            subscription.unsubscribe()
    finally:
        service.kill()
        if restarted is not None:
            assert restarted.stop() == 0


def test_stopped_service_takes_its_hands_offline_and_comes_back():
    service = Service(sim_config())
    try:
        with dh3.Client(domain=DOMAIN, default_timeout=DEADLINE) as client:
            two = client.wait_for_hand(spec(2), timeout=DEADLINE)
            assert two.wait_until(lambda s: s.online, timeout=DEADLINE)
            assert service.stop() == 0
            assert two.wait_until(lambda s: not s.online, timeout=60)
            service = Service(sim_config())
            assert two.wait_until(lambda s: s.online, timeout=60)
            assert two.initialize().ok
    finally:
        service.stop()
