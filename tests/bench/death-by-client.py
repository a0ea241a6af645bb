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
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
for folder in ("support", "scale", "web"):
    sys.path.insert(0, os.path.join(HERE, "..", folder))
from plantlib import given_binaries, percentile  # noqa: E402

#: Longer than any detection: a kind silent this long after the kill missed it.
GIVE_UP_S = 10.0
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


def one_kill(sig, dh3, webtest):
    """The milliseconds from the signal to each kind's OFFLINE (None: missed)."""
    address = webtest.hand(1)
    with webtest.service_and_web(config_text=CONFIG) as cell, \
            dh3.Client(domain=webtest.DOMAIN, default_timeout=GIVE_UP_S) as client:
        watchers = {
            "dh3ctl events": LineWatcher(
                [os.environ["DH3CTL"], "-d", str(webtest.DOMAIN), "--json", "events", address],
                "watching events", '"kind":"OFFLINE"'),
            "dh3-web stream": LineWatcher(["curl", "-sN", cell.url.rstrip("/") + "/api/stream"],
                                          f'"hand":"{address}"', '"kind":"OFFLINE"'),
        }
        try:
            hand = client.wait_for_hand(address, timeout=GIVE_UP_S)
            if not hand.wait_until(lambda s: s.online, timeout=GIVE_UP_S):
                raise RuntimeError("the hand never came online")
            python_seen = []

            def on_event(event):
                if event.kind == dh3.EventKind.OFFLINE and not python_seen:
                    python_seen.append(time.monotonic_ns())

            subscription = hand.subscribe(on_event)
            for kind, watcher in watchers.items():
                if not watcher.ready.wait(timeout=GIVE_UP_S):
                    raise RuntimeError(f"{kind} never showed the hand's service")
            # At a random phase of the service's assertions (every 100 ms).
            time.sleep(0.5 + random.random() * 0.3)
            killed_ns = time.monotonic_ns()
            cell.service.send_signal(sig)
            end = time.monotonic() + GIVE_UP_S
            while time.monotonic() < end and (
                    not python_seen or any(w.seen_ns is None for w in watchers.values())):
                time.sleep(0.01)  # polling what the watcher threads recorded
            subscription.unsubscribe()
            seen = {"Python module": python_seen[0] if python_seen else None}
            seen.update({kind: w.seen_ns for kind, w in watchers.items()})
            return {kind: None if ns is None else (ns - killed_ns) / 1e6
                    for kind, ns in seen.items()}
        finally:
            for watcher in watchers.values():
                watcher.stop()
            cell.service.kill()  # a frozen one too: it would not take the SIGTERM


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--kills", type=int, default=20)
    parser.add_argument("--signal", choices=["KILL", "STOP"], default="KILL")
    parser.add_argument("--json", help="write the figures to this file")
    args = parser.parse_args()
    build = os.path.abspath(args.build)
    programs = given_binaries(os.path.join(build, "service/app/dh3-service/dh3-service"),
                              os.path.join(build, "client/dh3ctl"),
                              os.path.join(build, "client/python"))
    os.environ["DH3_SERVICE"] = programs["dh3-service"]
    os.environ["DH3CTL"] = programs["dh3ctl"]
    os.environ["DH3_WEB"] = os.path.join(build, "client/dh3-web")
    sys.path.insert(0, programs["pythonpath"])
    import dh3  # noqa: PLC0415 (from the build tree named by --build)
    import webtest  # noqa: PLC0415 (reads the programs' paths from the environment)

    sig = signal.SIGKILL if args.signal == "KILL" else signal.SIGSTOP
    times = {}
    for _ in range(args.kills):
        for kind, ms in one_kill(sig, dh3, webtest).items():
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
