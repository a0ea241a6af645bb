"""Ctrl-C (SIGINT) ends a blocking call promptly with KeyboardInterrupt."""

import os
import signal
import subprocess
import sys
import textwrap

import dh3
from conftest import DEADLINE, DOMAIN, Service, sim_config, spec

SCRIPT = textwrap.dedent("""
    import sys, dh3
    client = dh3.Client(domain=int(sys.argv[1]), default_timeout=20.0)
    hand = client.wait_for_hand(sys.argv[2], timeout=20.0)
    print("calling", flush=True)
    try:
        # Initialization takes ten minutes on this service.
        reply = hand.initialize(timeout=600.0)
    except KeyboardInterrupt:
        print("interrupted in initialize", flush=True)
        sys.exit(3)
    print("initialize ended:", reply, flush=True)
""")


def test_ctrl_c_ends_a_blocking_call():
    service = Service(sim_config(init_time_ms=600000))
    try:
        with dh3.Client(domain=DOMAIN, default_timeout=DEADLINE) as watcher:
            one = watcher.wait_for_hand(spec(1), timeout=DEADLINE)
            assert one.wait_until(lambda s: s.online, timeout=DEADLINE)
            started = one.status().update_seq
            child = subprocess.Popen([sys.executable, "-c", SCRIPT, str(DOMAIN), spec(1)],
                                     stdout=subprocess.PIPE, text=True, env=os.environ.copy())
            try:
                assert child.stdout.readline().strip() == "calling"
                # The service took the INITIALIZE: the hand's status changed.
                assert one.wait_until(lambda s: s.update_seq != started, timeout=DEADLINE)
                child.send_signal(signal.SIGINT)
                out, _ = child.communicate(timeout=DEADLINE)
            finally:
                if child.poll() is None:
                    child.kill()
                    child.wait()
            assert child.returncode == 3, out
            assert "interrupted in initialize" in out
    finally:
        assert service.stop() == 0
