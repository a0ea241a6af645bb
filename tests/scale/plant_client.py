#!/usr/bin/python3
"""A client process of the plant (tests/scale/plant.sh), on the dh3 Python module.

    plant_client.py commander --hand cell01/bus0/1 --out FILE [DDS options]
    plant_client.py watcher --cell cell01 --hands 8 --out FILE [--follow] [DDS options]
    plant_client.py oneshot --hand cell01/bus0/1 --out FILE [DDS options]

Each writes JSON lines to --out, flushed as they happen, so the plant reads
them while the process runs; wall-clock times ("t") are time.time(), which
every network namespace of the plant shares.

commander: drives its own hand. Ready once its service is ready and the hand
  is known ({"ev": "ready"}). Commands nothing until SIGUSR1; then cycles
  initialize, move 50, grasp 40, release 100 and --reads register reads, one
  line per command ({"ev": "cmd", "cmd", "code", "ms"}), until SIGUSR2 (ends
  the cycle, then {"ev": "stopped"} with its command traffic so far);
  SIGUSR1 starts it again. A failed
  command is recorded and the cycle goes on after a short pause, so a
  commander outlives a service that leaves and comes back.
watcher: follows every status and event it receives and counts them, by its
  cell and in all. Ready once it has a status of each of its cell's --hands
  hands (--cell all: --hands is the plant's). A line for each change of a
  hand of its cell between online and offline (by status and by event);
  SIGUSR1 writes the counts so far and each hand's online flag and read_at_ns
  ({"ev": "mark"}).
oneshot: a client that joins a running plant, or starts with many others:
  ready as a commander, then one cycle, then --linger seconds; {"ev": "done",
  "ok": bool, and what reached it for its commands (own and other clients'
  replies)}; exit 0 only if every command answered OK.
--follow (not for a watcher of all): the client follows its cell
  (dh3.Client(follow=...)), so the services send it only that cell's
  statuses, events and service info.
SIGTERM (any role): {"ev": "exit"} and exit 0.
"""

import argparse
import json
import signal
import sys
import threading
import time

import dh3

out = None
out_lock = threading.Lock()


def emit(record: dict) -> None:
    record.setdefault("t", time.time())
    line = json.dumps(record, separators=(",", ":"))
    with out_lock:
        out.write(line + "\n")
        out.flush()


def make_client(args) -> dh3.Client:
    follow = ""
    if args.follow:
        # A commander or one-shot client its hand's service, a watcher its cell.
        follow = args.hand.split("/")[0] if args.hand else args.cell
    client = dh3.Client(domain=args.domain, participant_name=f"plant-{args.role}",
                        interfaces=args.interface, udp_only=args.udp_only,
                        discovery_servers=args.discovery_server,
                        default_timeout=args.timeout, follow=follow)
    if not client.connected():
        emit({"ev": "error", "what": "connect", "message": client.error()})
        sys.exit(1)
    return client


def wait_ready(client: dh3.Client, spec: str, deadline: float):
    """The hand once its service is ready and its status known; None at the deadline."""
    service = spec.split("/")[0]
    last = "deadline passed"
    while time.time() < deadline:
        step = min(5.0, max(0.1, deadline - time.time()))
        try:
            client.wait_for_service(service, timeout=step)
            return client.wait_for_hand(spec, timeout=step)
        except dh3.Error as error:
            last = error.message
    emit({"ev": "error", "what": "ready", "message": last})
    return None


def run_command(name: str, call) -> bool:
    start = time.perf_counter()
    reply = call()
    elapsed_ms = (time.perf_counter() - start) * 1000.0
    code = reply.code.name if hasattr(reply.code, "name") else str(reply.code)
    line = {"ev": "cmd", "cmd": name, "code": code, "ms": round(elapsed_ms, 3)}
    if not reply.ok:
        line["message"] = reply.message
    emit(line)
    return reply.ok


def one_cycle(hand: dh3.Hand, reads: int) -> bool:
    """initialize, move, grasp, release and some reads; False at the first failure."""
    steps = [("init", hand.initialize), ("move", lambda: hand.move_to(50)),
             ("grasp", lambda: hand.grasp(40)), ("release", lambda: hand.release(100))]
    steps += [("read", lambda: hand.read(dh3.reg.position))] * reads
    for name, call in steps:
        if not run_command(name, call):
            return False
    return True


def traffic(client: dh3.Client) -> dict:
    """What reached this client for its commands: its own replies, and other
    clients' replies that DDS delivered to it anyway."""
    t = client.command_traffic()
    w = client.watch_traffic()
    return {"requests": t.requests_written, "own_replies": t.own_replies,
            "foreign_replies": t.foreign_replies, "statuses_in": w.statuses,
            "dropped_on_arrival": w.dropped_on_arrival}


def commander(args) -> int:
    commanding = threading.Event()
    stopping = threading.Event()
    signal.signal(signal.SIGUSR1, lambda *_: (stopping.clear(), commanding.set()))
    signal.signal(signal.SIGUSR2, lambda *_: stopping.set())
    client = make_client(args)
    hand = wait_ready(client, args.hand, time.time() + args.ready_deadline)
    if hand is None:
        return 1
    emit({"ev": "ready"})
    while True:
        # Idle between phases without waking: a commander at rest costs what
        # its DDS participant costs, nothing of its own.
        while not commanding.wait(3600):
            pass
        emit({"ev": "commanding"})
        cycles = 0
        while not stopping.is_set():
            if one_cycle(hand, args.reads):
                cycles += 1
            else:
                time.sleep(0.2)  # a service away: try again, do not spin
        commanding.clear()
        emit({"ev": "stopped", "cycles": cycles, **traffic(client)})


def oneshot(args) -> int:
    client = make_client(args)
    hand = wait_ready(client, args.hand, time.time() + args.ready_deadline)
    if hand is None:
        emit({"ev": "done", "ok": False})
        return 1
    emit({"ev": "ready"})
    ok = one_cycle(hand, args.reads)
    # Replies kept for earlier clients (TRANSIENT_LOCAL) come as it joins;
    # give them a moment to arrive before counting.
    time.sleep(args.linger)
    emit({"ev": "done", "ok": ok, **traffic(client)})
    return 0 if ok else 1


def watcher(args) -> int:
    lock = threading.Lock()
    counts = {"status_all": 0, "status_cell": 0, "events_all": 0, "events_cell": 0}
    online = {}     # hand -> bool, from the latest status of it
    read_at = {}    # hand -> read_at_ns of the latest status of it
    ready = threading.Event()
    mine = (lambda a: True) if args.cell == "all" else (lambda a: a.service == args.cell)

    def on_status(status):
        address = status.address
        with lock:
            counts["status_all"] += 1
            if not mine(address):
                return
            counts["status_cell"] += 1
            key = str(address)
            was = online.get(key)
            online[key] = status.online
            read_at[key] = status.read_at_ns
            if was is not None and was != status.online:
                emit({"ev": "online" if status.online else "offline", "hand": key, "by": "status",
                      "service_lost": status.service_lost})
            if not ready.is_set() and len(online) >= args.hands:
                ready.set()
                emit({"ev": "ready"})

    def on_event(event):
        with lock:
            counts["events_all"] += 1
            if not mine(event.hand):
                return
            counts["events_cell"] += 1
            kind = event.kind.name if hasattr(event.kind, "name") else str(event.kind)
            if kind in ("OFFLINE", "ONLINE"):
                emit({"ev": "event", "kind": kind, "hand": str(event.hand),
                      "from_client": event.from_client})

    def mark(*_):
        with lock:
            emit({"ev": "mark", **counts, "online": dict(online), "read_at": dict(read_at)})

    client = make_client(args)
    signal.signal(signal.SIGUSR1, mark)
    subscriptions = [client.subscribe_status(on_status), client.subscribe(on_event)]
    while subscriptions:  # they end with the process (SIGTERM)
        signal.pause()
    return 0


def main() -> int:
    global out
    parser = argparse.ArgumentParser(description="a client process of the dh3 plant")
    parser.add_argument("role", choices=["commander", "watcher", "oneshot"])
    parser.add_argument("--out", required=True, help="JSON lines are written here")
    parser.add_argument("--hand", help="commander, oneshot: SERVICE/BUS/ID")
    parser.add_argument("--cell", help="watcher: the service to follow, or all")
    parser.add_argument("--hands", type=int, default=8,
                        help="watcher: hands in its cell (ready once all are seen)")
    parser.add_argument("--reads", type=int, default=5, help="register reads per cycle")
    parser.add_argument("--linger", type=float, default=0.0,
                        help="oneshot: seconds to stay after its cycle before counting its traffic")
    parser.add_argument("--follow", action="store_true",
                        help="follow only its cell (the service of --hand, or --cell): the "
                             "services send it nothing of the other cells")
    parser.add_argument("-d", "--domain", type=int, default=0)
    parser.add_argument("-i", "--interface", action="append", default=[])
    parser.add_argument("--udp-only", action="store_true")
    parser.add_argument("--discovery-server", action="append", default=[])
    parser.add_argument("--timeout", type=float, default=20.0, help="seconds per command")
    parser.add_argument("--ready-deadline", type=float, default=300.0,
                        help="seconds to wait for the service and hand")
    args = parser.parse_args()
    out = open(args.out, "a", buffering=1)
    emit({"ev": "start"})
    signal.signal(signal.SIGTERM, lambda *_: (emit({"ev": "exit"}), sys.exit(0)))
    if args.role == "commander":
        return commander(args)
    if args.role == "oneshot":
        return oneshot(args)
    return watcher(args)


if __name__ == "__main__":
    sys.exit(main())
