#!/usr/bin/python3
"""Death detection by client kind: how long after dh3-service is killed (or
frozen) each kind of client built on the client library reports its hands
OFFLINE: the Python module (its event callback), `dh3ctl --json events` (the
line on its standard output) and dh3-web (the OFFLINE event on /api/stream).
One service on the simulator and one watcher of each kind, on loopback; each
kill has a new service and new watchers. The C++ library alone is
bench_failover's. Prints a table (BENCHMARKS.md, "Death detection").

    /usr/bin/python3 tests/bench/death-by-client.py [--build build] [--kills 20] [--signal STOP]
"""

import argparse
import json
import os
import random
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "support"))
from test_domain import pick_domain  # noqa: E402

#: Longer than any detection: a kind silent this long after the kill missed it.
GIVE_UP_S = 10.0
SERVICE = f"death{os.getpid()}"
CONFIG = "buses:\n  - name: bus0\n    spec: sim\n    hands: [{id: 1}, {id: 2}]\n"


class LineWatcher:
    """A child process whose output lines are read as they come: when the
    first holding `ready_text`, and the first holding `seen_text`, arrived."""

    def __init__(self, argv, ready_text, seen_text):
        self.ready = threading.Event()
        self.seen_ns = None
        self.process = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                        stderr=subprocess.STDOUT, text=True)
        self._thread = threading.Thread(target=self._read, args=(ready_text, seen_text),
                                        daemon=True)
        self._thread.start()

    def _read(self, ready_text, seen_text):
        for line in self.process.stdout:
            if ready_text in line:
                self.ready.set()
            if self.seen_ns is None and seen_text in line:
                self.seen_ns = time.monotonic_ns()

    def stop(self):
        self.process.kill()
        self.process.wait()


def free_port():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def one_kill(build, domain, sig, dh3):
    """The milliseconds from the signal to each kind's OFFLINE (None: missed)."""
    config = tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False)
    config.write(CONFIG)
    config.close()
    service = subprocess.Popen(
        [os.path.join(build, "service/app/dh3-service/dh3-service"), "--config", config.name,
         "--domain", str(domain), "--name", SERVICE, "--log-level", "warn"],
        stdin=subprocess.DEVNULL)
    watchers = {}
    web = None
    client = dh3.Client(domain=domain, default_timeout=GIVE_UP_S)
    try:
        hand = client.wait_for_hand(f"{SERVICE}/bus0/1", timeout=GIVE_UP_S)
        if not hand.wait_until(lambda s: s.online, timeout=GIVE_UP_S):
            raise RuntimeError("the hand never came online")
        python_seen = []

        def on_event(event):
            if event.kind == dh3.EventKind.OFFLINE and not python_seen:
                python_seen.append(time.monotonic_ns())

        subscription = hand.subscribe(on_event)
        port = free_port()
        watchers["dh3ctl events"] = LineWatcher(
            [os.path.join(build, "client/dh3ctl"), "-d", str(domain), "--json", "events",
             f"{SERVICE}/bus0/1"], "watching events", '"kind":"OFFLINE"')
        web = LineWatcher(
            [os.path.join(build, "client/dh3-web"), "-d", str(domain), "--listen",
             f"127.0.0.1:{port}", "--log-level", "warn"], "never", "never")
        stream = None
        deadline = time.monotonic() + GIVE_UP_S
        while stream is None and time.monotonic() < deadline:
            try:
                stream = LineWatcher(["curl", "-sN", f"http://127.0.0.1:{port}/api/stream"],
                                     f'"hand":"{SERVICE}/bus0/1"', '"kind":"OFFLINE"')
                if not stream.ready.wait(timeout=2):
                    stream.stop()
                    stream = None
            except OSError:
                stream = None
        if stream is None:
            raise RuntimeError("dh3-web's stream never showed the hand")
        watchers["dh3-web stream"] = stream
        if not watchers["dh3ctl events"].ready.wait(timeout=GIVE_UP_S):
            raise RuntimeError("dh3ctl events never found the service")
        # At a random phase of the service's assertions (every 100 ms).
        time.sleep(0.5 + random.random() * 0.3)
        killed_ns = time.monotonic_ns()
        service.send_signal(sig)
        end = time.monotonic() + GIVE_UP_S
        while time.monotonic() < end and (
                not python_seen or any(w.seen_ns is None for w in watchers.values())):
            time.sleep(0.01)  # polling what the watcher threads recorded
        seen = {"Python module": python_seen[0] if python_seen else None}
        seen.update({kind: w.seen_ns for kind, w in watchers.items()})
        subscription.unsubscribe()
        return {kind: None if ns is None else (ns - killed_ns) / 1e6 for kind, ns in seen.items()}
    finally:
        for watcher in watchers.values():
            watcher.stop()
        if web is not None:
            web.stop()
        client.close()
        service.kill()
        service.wait()
        os.remove(config.name)


def percentile(values, p):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(p * (len(ordered) - 1) + 0.5))]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--kills", type=int, default=20)
    parser.add_argument("--signal", choices=["KILL", "STOP"], default="KILL")
    parser.add_argument("--json", help="write the figures to this file")
    args = parser.parse_args()
    build = os.path.abspath(args.build)
    sys.path.insert(0, os.path.join(build, "client/python"))
    import dh3  # noqa: PLC0415 (built in the build tree named by --build)

    domain = pick_domain()
    sig = signal.SIGKILL if args.signal == "KILL" else signal.SIGSTOP
    times = {}
    for _ in range(args.kills):
        for kind, ms in one_kill(build, domain, sig, dh3).items():
            times.setdefault(kind, []).append(ms)
    print(f"death detection, SIG{args.signal} of dh3-service, {args.kills} kills, "
          f"signal to the hand OFFLINE at the client:")
    print("| client | kills | missed | OFFLINE p50 / p99 / max |")
    print("|--------|-------|--------|--------------------------|")
    figures = {}
    for kind, values in times.items():
        seen = [ms for ms in values if ms is not None]
        missed = len(values) - len(seen)
        figures[kind] = {"kills": len(values), "missed": missed, "ms": seen}
        row = (f"{percentile(seen, 0.5):.0f} / {percentile(seen, 0.99):.0f} / {max(seen):.0f} ms"
               if seen else "none seen")
        print(f"| {kind} | {len(values)} | {missed} | {row} |")
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"signal": args.signal, "clients": figures}, out, indent=1)


if __name__ == "__main__":
    main()
