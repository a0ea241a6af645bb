"""A service killed or frozen is seen by the Python module well before Fast
DDS's 20 s participant lease would have told (docs/failover.md): its pending
call ends SERVICE_LOST and its hand goes offline, each saying why. The
deadlines are generous for a loaded machine and inside that lease."""

import signal
import threading

import dh3
from conftest import DEADLINE, DOMAIN, SERVICE, Service, sim_config, spec

BEFORE_PARTICIPANT_LEASE = 12


def death_is_seen(sig):
    service = Service(sim_config(init_time_ms=600000))
    try:
        with dh3.Client(domain=DOMAIN, default_timeout=DEADLINE) as client:
            two = client.wait_for_hand(spec(2), timeout=DEADLINE)
            assert two.wait_until(lambda s: s.online, timeout=DEADLINE)
            offline = []
            went_offline = threading.Event()

            def on_event(event):
                if event.kind == dh3.EventKind.OFFLINE:
                    offline.append(event)
                    went_offline.set()

            subscription = two.subscribe(on_event)
            pending = two.initialize_async(timeout=120)
            # Requests from one client arrive in order: once another hand's
            # read is answered, the service has the INITIALIZE (ten minutes).
            probe = client.hand(dh3.HandAddress(SERVICE, "bus0", 3)).read(dh3.reg.position)
            assert probe.ok, probe
            service.process.send_signal(sig)

            lost = pending.result(timeout=BEFORE_PARTICIPANT_LEASE)
            assert lost.code == dh3.Code.SERVICE_LOST, lost
            assert "stopped asserting it lives" in lost.message
            assert went_offline.wait(timeout=BEFORE_PARTICIPANT_LEASE)
            assert "killed, frozen or cut off" in offline[0].message
            assert not two.online()
            subscription.unsubscribe()
    finally:
        service.kill()


def test_a_killed_service_is_seen_before_the_participant_lease():
    death_is_seen(signal.SIGKILL)


def test_a_frozen_service_is_seen_before_the_participant_lease():
    death_is_seen(signal.SIGSTOP)
