#!/usr/bin/python3
"""Runs plants of the given sizes with the given discovery setups, one after
the other, and measures what each costs; one JSON file per run, and tables.
Started by plant.sh (which checks for root and cleans up behind it).

One run:
 1. the network (plantlib.Plant), the discovery-server pair (server setup),
    S dh3-service hosts with H simulated hands each (cell01..cellSS), up;
 2. every client started at the same moment: per cell a commander (Python,
    drives hand 1 of its cell) and a watcher of that cell (Python; cell01's
    alone on host c00, so that host's traffic is one watcher's), and two
    watchers of the whole plant (`dh3ctl --json status --watch`, `dh3ctl
    events`), spread over the client hosts; time until each is ready;
 3. at rest (--rest seconds): nobody commands;
 4. commanding (--command seconds): every commander cycles init, move,
    grasp, release and five register reads;
 5. per phase: CPU (utime + stime from /proc) and RSS of every process,
    bytes through the bridge (sent and delivered, discovery and data apart),
    what reached cell01's watcher, and round trips of the reads.
"""

import argparse
import datetime
import json
import os
import shutil
import signal
import sys
import time

sys.dont_write_bytecode = True  # nothing written into the source tree
import plantlib  # noqa: E402
from plantlib import Plant, percentile  # noqa: E402

KINDS = [("service", "dh3-service"), ("discovery-server", "discovery server"),
         ("py-commander", "commander (py)"), ("py-watcher", "cell watcher (py)"),
         ("py-plantwatcher", "plant watcher (py)"),
         ("ctl-status", "dh3ctl status --watch"), ("ctl-events", "dh3ctl events")]


def log(*args):
    print(*args, flush=True)


def snapshot(plant):
    return {"t": time.time(), "machine": plantlib.machine_cpu(),
            "procs": {p.name: p.stat() for p in plant.procs},
            "net": plant.read_counters()}


def phase_costs(plant, a, b):
    dt = b["t"] - a["t"]
    per_proc = {}
    for p in plant.procs:
        sa, sb = a["procs"].get(p.name), b["procs"].get(p.name)
        if sa and sb:
            per_proc[p.name] = {"kind": p.kind, "host": p.host,
                                "cpu_pct": round((sb[0] - sa[0]) / dt * 100.0, 3),
                                "rss_kib": sb[1]}
    by_kind = {}
    for kind, _ in KINDS:
        rows = [v for v in per_proc.values() if v["kind"] == kind]
        if rows:
            cpu = [r["cpu_pct"] for r in rows]
            rss = [r["rss_kib"] for r in rows]
            by_kind[kind] = {"count": len(rows), "cpu_pct_mean": round(sum(cpu) / len(cpu), 3),
                             "cpu_pct_max": max(cpu), "cpu_pct_sum": round(sum(cpu), 3),
                             "rss_kib_mean": round(sum(rss) / len(rss)), "rss_kib_max": max(rss)}
    na, nb = a["net"], b["net"]
    ports = nb["ports"].keys()

    def rate(values):
        return round(values / dt)

    net = {"sent_Bps": rate(sum(nb["ports"][p]["rx"] - na["ports"][p]["rx"] for p in ports)),
           "delivered_Bps": rate(sum(nb["ports"][p]["tx"] - na["ports"][p]["tx"] for p in ports)),
           "sent_packets_ps": rate(sum(nb["ports"][p]["rx_packets"] - na["ports"][p]["rx_packets"]
                                       for p in ports))}
    for name in nb["nft"]:
        net[f"{name}_Bps"] = rate(nb["nft"][name] - na["nft"].get(name, 0))
    hosts = {p: {"rx_Bps": rate(nb["ports"][p]["tx"] - na["ports"][p]["tx"]),
                 "tx_Bps": rate(nb["ports"][p]["rx"] - na["ports"][p]["rx"])} for p in ports}
    cpu_total = sum(v["cpu_pct"] for v in per_proc.values())
    # What the machine did meanwhile, in % of one core: the plant's processes
    # and everybody else's (the other engineers' builds on this machine).
    busy = (b["machine"][0] - a["machine"][0]) / dt * 100.0
    steal = (b["machine"][1] - a["machine"][1]) / dt * 100.0
    machine = {"busy_pct": round(busy, 1), "others_pct": round(max(0.0, busy - cpu_total), 1),
               "steal_pct": round(steal, 1), "cores": os.cpu_count()}
    return {"seconds": round(dt, 2), "by_kind": by_kind, "net": net, "hosts": hosts,
            "cpu_pct_total": round(cpu_total, 2), "machine": machine, "procs": per_proc}


def watcher_rates(ma, mb, dt):
    if not ma or not mb:
        return None
    return {k: round((mb[k] - ma[k]) / dt, 2)
            for k in ("status_all", "status_cell", "events_all", "events_cell")}


def command_stats(commanders, t0, t1):
    reads, codes, ended_in_window = [], {}, 0
    for c in commanders:
        for r in c.lines():
            if r.get("ev") != "cmd":
                continue
            # Every command sent in the window, also one that ends after it
            # (a NO_REPLY ends at its timeout, after the window).
            sent = r["t"] - r["ms"] / 1000.0
            if not (t0 <= r["t"] <= t1 or t0 <= sent <= t1):
                continue
            ended_in_window += t0 <= r["t"] <= t1
            codes[r["code"]] = codes.get(r["code"], 0) + 1
            if r["cmd"] == "read" and r["code"] == "OK":
                reads.append(r["ms"])
    total = sum(codes.values())
    return {"commands": total, "per_s": round(ended_in_window / (t1 - t0), 1),
            "codes": codes, "failed": total - codes.get("OK", 0),
            "read_ms_p50": percentile(reads, 0.5), "read_ms_p99": percentile(reads, 0.99),
            "read_ms_max": max(reads) if reads else None, "reads": len(reads)}


def run_one(bins, args, services, discovery):
    client_hosts = args.client_hosts or max(2, services // 2)
    started = datetime.datetime.now(datetime.timezone.utc)
    result = {"date": started.strftime("%Y-%m-%d %H:%M UTC"), "services": services,
              "hands": args.hands, "discovery": discovery, "client_hosts": client_hosts,
              "load_before": plantlib.loadavg(), "command": " ".join(sys.argv),
              "follow": args.follow}
    log(f"== plant: {services} services x {args.hands} hands, {discovery} discovery, "
        f"{client_hosts + 1} client hosts; load average {result['load_before']}")
    with Plant(bins, services=services, hands=args.hands, client_hosts=client_hosts,
               discovery=discovery, domain=args.domain, service_log_level=args.service_log_level,
               workdir=os.path.join(args.workdir, f"s{services}-{discovery}")) as plant:
        plant.follow = args.follow
        plant.start_discovery_servers()
        t_services = time.time()
        plant.start_services()
        plant.wait_services(args.ready_deadline)
        result["services_up_s"] = round(time.time() - t_services, 2)
        time.sleep(args.settle)

        # Every client at once, or one every --stagger seconds.
        at_start = snapshot(plant)
        t_start = time.time()

        def paced(proc):
            if args.stagger > 0:
                time.sleep(args.stagger)
            return proc

        commanders, watchers = [], []
        measured = paced(plant.start_watcher("c00", plant.cell(1), name="watch-cell01-measured"))
        watchers.append(measured)
        host_cycle = [f"c{i:02d}" for i in range(1, client_hosts + 1)]
        n = 0
        for i in range(1, services + 1):
            commanders.append(paced(plant.start_commander(host_cycle[n % client_hosts],
                                                          f"{plant.cell(i)}/bus0/1")))
            n += 1
            if i > 1:
                watchers.append(paced(plant.start_watcher(host_cycle[n % client_hosts],
                                                          plant.cell(i))))
                n += 1
        watchers.append(paced(plant.start_watcher(host_cycle[n % client_hosts], "all",
                                                  name="watch-plant")))
        ctl = [paced(plant.start_ctl_watcher(host_cycle[(n + 1) % client_hosts], "events",
                                             "ctl-events"))]
        if args.ctl_status:
            ctl.append(paced(plant.start_ctl_watcher(host_cycle[(n + 2) % client_hosts],
                                                     "status", "ctl-status")))
        clients = [measured] + commanders + watchers[1:] + ctl
        result["clients"] = len(clients)
        result["stagger_s"] = args.stagger
        log(f"   {len(clients)} clients started in {time.time() - t_start:.2f} s")

        end = time.time() + args.ready_deadline
        while time.time() < end:
            if all(plant.ready_time(c) for c in clients):
                break
            time.sleep(0.2)
        startup = phase_costs(plant, at_start, snapshot(plant))
        ready = {c.name: plant.ready_time(c) for c in clients}
        # Each from its own start: the same as from the common start when
        # they start together.
        since_start = {c.name: ready[c.name] - c.launched for c in clients if ready[c.name]}
        latencies = list(since_start.values())
        by_kind = {}
        for c in clients:
            if c.name in since_start:
                by_kind.setdefault(c.kind, []).append(since_start[c.name])
        result["ready"] = {
            "p50_s": round(percentile(latencies, 0.5), 2) if latencies else None,
            "max_s": round(max(latencies), 2) if latencies else None,
            "not_ready": [name for name, t in ready.items() if not t],
            "by_kind_max_s": {k: round(max(v), 2) for k, v in by_kind.items()},
            "load": plantlib.loadavg(), "machine": startup["machine"],
            "plant_cpu_pct": startup["cpu_pct_total"]}
        log(f"   ready: p50 {result['ready']['p50_s']} s, max {result['ready']['max_s']} s, "
            f"not ready {len(result['ready']['not_ready'])}")
        time.sleep(args.settle)

        # At rest.
        a = snapshot(plant)
        ma = plant.mark(watchers)
        time.sleep(args.rest)
        b = snapshot(plant)
        mb = plant.mark(watchers)
        rest = phase_costs(plant, a, b)
        rest["watcher"] = watcher_rates(ma.get(measured.name), mb.get(measured.name), b["t"] - a["t"])
        rest["load"] = plantlib.loadavg()
        result["rest"] = rest

        # Commanding.
        t_commanding = time.time()  # before the signals: a first command may precede c0
        for c in commanders:
            c.signal(signal.SIGUSR1)
        c0 = snapshot(plant)
        mc = plant.mark(watchers)
        time.sleep(args.command)
        d = snapshot(plant)
        md = plant.mark(watchers)
        for c in commanders:
            c.signal(signal.SIGUSR2)
        cmd = phase_costs(plant, c0, d)
        cmd["watcher"] = watcher_rates(mc.get(measured.name), md.get(measured.name), d["t"] - c0["t"])
        cmd["load"] = plantlib.loadavg()
        result["commanding"] = cmd
        for c in commanders:
            if not plant.ready_time(c):
                continue  # never ready: it commands nothing, and never stops
            plant_wait = time.time() + 60
            while time.time() < plant_wait and not c.first("stopped"):
                time.sleep(0.1)
        # Once they stopped: a command still waiting for its reply has ended.
        cmd["commands"] = command_stats(commanders, t_commanding, d["t"])
        stopped = [c.first("stopped") or {} for c in commanders]
        result["commander_traffic"] = {
            k: sum(r.get(k, 0) for r in stopped) for k in ("requests", "own_replies", "foreign_replies")}

        # A client that joins the busy plant: how long until it is ready, and
        # how many replies to other clients it is sent as it joins.
        joiner = plant.start_oneshot("c01", f"{plant.cell(1)}/bus0/2", "late-joiner", linger=3.0)
        end = time.time() + args.ready_deadline
        while time.time() < end and joiner.popen.poll() is None:
            time.sleep(0.2)
        done, ready_rec = joiner.first("done") or {}, joiner.first("ready")
        result["late_joiner"] = {
            "ready_s": round(ready_rec["t"] - joiner.launched, 2) if ready_rec else None,
            "ok": bool(done.get("ok")), "own_replies": done.get("own_replies"),
            "foreign_replies": done.get("foreign_replies")}
        log(f"   late joiner: ready in {result['late_joiner']['ready_s']} s, "
            f"{done.get('foreign_replies')} replies to other clients reached it")
        result["exited_early"] = [p.name for p in plant.procs
                                  if not p.alive() and p is not joiner]
    result["load_after"] = plantlib.loadavg()
    return result


def setup(r):
    """The setup column: discovery, and "+f" where the clients followed their cell."""
    return r["discovery"] + ("+f" if r.get("follow") else "")


def mib(kib):
    return f"{kib / 1024:.1f}"


def print_tables(results):
    staggered = sorted({r.get("stagger_s", 0) for r in results} - {0})
    how = f"one every {staggered[0]} s" if staggered else "together"
    log(f"\nStart-up (clients started {how} once every service was up; ready: from each "
        f"one's start)")
    log(f"{'setup':8} {'S x H':>7} {'clients':>7} {'ready p50':>9} {'max':>7} {'not ready':>9}  "
        f"load  others' CPU %")
    for r in results:
        rd = r["ready"]
        log(f"{setup(r):8} {r['services']:>3} x {r['hands']:<2} {r['clients']:>7} "
            f"{rd['p50_s'] if rd['p50_s'] is not None else '-':>8}s {rd['max_s'] or '-':>6}s "
            f"{len(rd['not_ready']):>9}  {r['load_before'][0]:>4.1f}  {rd['machine']['others_pct']:>6.1f}")
    for phase, title in (("rest", "At rest"), ("commanding", "Commanding")):
        log(f"\n{title}: CPU % of one core per process (mean / max) and RSS MiB (mean); the "
            f"plant's processes together, and the machine's other processes meanwhile")
        log(f"{'setup':8} {'S x H':>7}  {'service':>14} {'commander py':>14} {'cell watch py':>14} "
            f"{'plant watch py':>14} {'ctl events':>10} {'disc srv':>10} {'all procs':>9} {'others':>6}")
        for r in results:
            k = r[phase]["by_kind"]

            def cell(kind, width=14):
                if kind not in k:
                    return f"{'-':>{width}}"
                v = k[kind]
                text = (f"{v['cpu_pct_mean']:.1f}/{v['cpu_pct_max']:.1f} {mib(v['rss_kib_mean'])}"
                        if width == 14 else f"{v['cpu_pct_mean']:.1f} {mib(v['rss_kib_mean'])}")
                return f"{text:>{width}}"
            log(f"{setup(r):8} {r['services']:>3} x {r['hands']:<2}  {cell('service')} "
                f"{cell('py-commander')} {cell('py-watcher')} {cell('py-plantwatcher')} "
                f"{cell('ctl-events', 10)} {cell('discovery-server', 10)} "
                f"{r[phase]['cpu_pct_total']:>9.1f} {r[phase]['machine']['others_pct']:>6.1f}")
            if "ctl-status" in k:
                log(f"{'':18}dh3ctl status --watch: {k['ctl-status']['cpu_pct_mean']:.1f} % "
                    f"{mib(k['ctl-status']['rss_kib_mean'])} MiB")
    log("\nBridge (kB/s: sent by the hosts, delivered to them; discovery / data by UDP port)")
    log(f"{'setup':8} {'S x H':>7}  {'rest sent':>9} {'disc':>7} {'data':>7} {'dlv':>8}   "
        f"{'cmd sent':>9} {'disc':>7} {'data':>7} {'dlv':>8}")
    for r in results:
        def cols(n):
            return (f"{n['sent_Bps'] / 1000:>9.1f} {n['sent_disc_Bps'] / 1000:>7.1f} "
                    f"{n['sent_data_Bps'] / 1000:>7.1f} {n['delivered_Bps'] / 1000:>8.1f}")
        log(f"{setup(r):8} {r['services']:>3} x {r['hands']:<2}  {cols(r['rest']['net'])}   "
            f"{cols(r['commanding']['net'])}")
    log("\nCommands and one cell's watcher (cell01's, alone on its host)")
    log(f"{'setup':8} {'S x H':>7}  {'cmds/s':>6} {'failed':>6} {'read p50':>8} {'p99 ms':>7}   "
        f"{'rest: status/s all':>18} {'cell':>5} {'kB/s in':>7}   {'cmd: status/s all':>17} "
        f"{'cell':>5} {'events/s':>8} {'kB/s in':>7}")
    for r in results:
        c = r["commanding"]["commands"]
        wr, wc = r["rest"]["watcher"] or {}, r["commanding"]["watcher"] or {}
        hr = r["rest"]["hosts"].get("c00", {}).get("rx_Bps", 0) / 1000
        hc = r["commanding"]["hosts"].get("c00", {}).get("rx_Bps", 0) / 1000

        def ms(v):
            return f"{v:.2f}" if v is not None else "-"
        log(f"{setup(r):8} {r['services']:>3} x {r['hands']:<2}  {c['per_s']:>6} {c['failed']:>6} "
            f"{ms(c['read_ms_p50']):>8} {ms(c['read_ms_p99']):>7}   "
            f"{wr.get('status_all', '-'):>18} {wr.get('status_cell', '-'):>5} {hr:>7.1f}   "
            f"{wc.get('status_all', '-'):>17} {wc.get('status_cell', '-'):>5} "
            f"{wc.get('events_all', '-'):>8} {hc:>7.1f}")
    log("\nA client joining after the commanding (one cycle of cell01's hand 2), and the commanders")
    log(f"{'setup':8} {'S x H':>7}  {'ready s':>7} {'ok':>3} {'replies to others sent to it':>28}   "
        f"{'commanders: requests':>20} {'own replies':>11} {'others':>6}")
    for r in results:
        j, t = r["late_joiner"], r["commander_traffic"]
        log(f"{setup(r):8} {r['services']:>3} x {r['hands']:<2}  {j['ready_s'] or '-':>7} "
            f"{'yes' if j['ok'] else 'NO':>3} {j['foreign_replies'] if j['foreign_replies'] is not None else '-':>28}   "
            f"{t['requests']:>20} {t['own_replies']:>11} {t['foreign_replies']:>6}")


def main():
    parser = argparse.ArgumentParser(description="the dh3 plant benchmark (run through plant.sh)")
    parser.add_argument("--build", default="", help="build tree with the programs and the module")
    parser.add_argument("--service", help="instead of --build: the dh3-service program")
    parser.add_argument("--ctl", help="instead of --build: the dh3ctl program")
    parser.add_argument("--pythonpath", help="instead of --build: the folder of the dh3 package")
    parser.add_argument("--services", default="2", help="plant sizes, comma-separated (services)")
    parser.add_argument("--hands", type=int, default=8, help="simulated hands per service")
    parser.add_argument("--discovery", default="simple,server",
                        help="simple, server or both (comma-separated)")
    parser.add_argument("--client-hosts", type=int, default=0,
                        help="client hosts besides c00 (default: services / 2, at least 2)")
    parser.add_argument("--rest", type=float, default=20.0, help="seconds at rest")
    parser.add_argument("--command", type=float, default=20.0, help="seconds commanding")
    parser.add_argument("--settle", type=float, default=3.0,
                        help="seconds after the services are up, and after every client is ready")
    parser.add_argument("--ready-deadline", type=float, default=180.0)
    parser.add_argument("--domain", type=int, default=0)
    parser.add_argument("--stagger", type=float, default=0.0,
                        help="seconds between client starts (default 0: all at once); "
                             "ready times are then from each client's own start")
    parser.add_argument("--ctl-status", action="store_true",
                        help="also a `dh3ctl --json status --watch` of the whole plant (it spins a "
                             "core when its output is not a terminal: off by default)")
    parser.add_argument("--follow", action="store_true",
                        help="the commanders, cell watchers and the late joiner follow their cell "
                             "(dh3.Client(follow=...)): the services send each only its cell's "
                             "statuses and events; the plant watchers still follow everything")
    parser.add_argument("--service-log-level", default="info",
                        help="the services' --log-level; debug logs every request and every "
                             "client participant and request writer a service finds or loses")
    parser.add_argument("--out", default="", help="directory for the JSON files (default BUILD/scale)")
    parser.add_argument("--workdir", default="", help="logs (default: a fresh folder in /tmp)")
    parser.add_argument("--check", action="store_true",
                        help="exit 1 unless every client was ready, no command failed and no "
                             "process ended early (the ctest scale.plant_runs)")
    parser.add_argument("--time-limit", type=float, default=0,
                        help="seconds before it gives up and cleans up (0: none)")
    args = parser.parse_args()
    if args.service:
        bins = plantlib.given_binaries(args.service, args.ctl, args.pythonpath)
    elif args.build:
        bins = plantlib.find_binaries(args.build)
    else:
        parser.error("--build or --service, --ctl and --pythonpath")
    if not args.out and not args.build:
        parser.error("--out is needed without --build")
    args.out = args.out or os.path.join(args.build, "scale")
    os.makedirs(args.out, exist_ok=True)
    args.workdir = args.workdir or f"/tmp/dh3-plant-{os.getpid()}"
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    if args.time_limit:
        def out_of_time(*_):
            raise plantlib.PlantError(f"time limit ({args.time_limit:.0f} s) passed")
        signal.signal(signal.SIGALRM, out_of_time)
        signal.alarm(int(args.time_limit))
    results = []
    for services in [int(s) for s in args.services.split(",")]:
        for discovery in args.discovery.split(","):
            result = run_one(bins, args, services, discovery)
            stamp = time.strftime("%Y%m%d-%H%M%S", time.gmtime())
            kind = discovery + ("-follow" if args.follow else "")
            path = os.path.join(args.out, f"plant-{kind}-{services}x{args.hands}-{stamp}.json")
            with open(path, "w") as f:
                json.dump(result, f, indent=1)
            log(f"   written {path}")
            results.append(result)
            print_tables([result])
    if len(results) > 1:
        log("\n==== all runs")
        print_tables(results)
    if args.check:
        problems = check(results)
        for problem in problems:
            log(f"FAILED: {problem}")
        if problems:
            log(f"logs in {args.workdir}")
            return 1
        shutil.rmtree(args.workdir, ignore_errors=True)
        log("plant_run: every client ready, no command failed, no process ended early")
        return 0
    log(f"\nlogs in {args.workdir}")
    return 0


def check(results):
    problems = []
    for r in results:
        what = f"{setup(r)} {r['services']}x{r['hands']}"
        if r["ready"]["not_ready"]:
            problems.append(f"{what}: not ready: {', '.join(r['ready']['not_ready'])}")
        cmds = r["commanding"]["commands"]
        if cmds["commands"] == 0 or cmds["failed"]:
            problems.append(f"{what}: {cmds['commands']} commands, {cmds['failed']} failed "
                            f"{cmds['codes']}")
        if not r["late_joiner"]["ok"]:
            problems.append(f"{what}: the late joiner failed")
        if r["exited_early"]:
            problems.append(f"{what}: ended early: {', '.join(r['exited_early'])}")
    return problems


if __name__ == "__main__":
    try:
        sys.exit(main())
    except plantlib.Skip as skip:
        print(f"SKIP: {skip}")
        sys.exit(77)
