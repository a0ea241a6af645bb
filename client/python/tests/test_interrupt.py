"""Ctrl-C (SIGINT) ends a blocking call promptly with KeyboardInterrupt."""

import os
import signal
import subprocess
import sys
import textwrap

import dh3
from conftest import DEADLINE, DOMAIN, Service, sim_config, spec

SCRIPT = textwrap.dedent("""
    import sys, threading, dh3
    client = dh3.Client(domain=int(sys.argv[1]), default_timeout=20.0)
    hand = client.wait_for_hand(sys.argv[2], timeout=20.0)
    main = threading.main_thread().ident

    def announce():
        # Says "in call" once the main thread is on the initialize() line and
        # this thread has since made a call of its own to the same service
        # (the main thread had all that time to get into initialize()).
        while sys._current_frames()[main].f_lineno != CALL_LINE:
            threading.Event().wait(0.01)
        print("read:", hand.read(dh3.reg.position).code, flush=True)
        print("in call", flush=True)

    CALL_LINE = sys._getframe().f_lineno + 4
    threading.Thread(target=announce, daemon=True).start()
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
            child = subprocess.Popen([sys.executable, "-c", SCRIPT, str(DOMAIN), spec(1)],
                                     stdout=subprocess.PIPE, text=True, env=os.environ.copy())
            try:
                assert child.stdout.readline().strip() == "read: OK"
                assert child.stdout.readline().strip() == "in call"
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
