#!/usr/bin/python3
"""PNG plots of the plant's costs against its size, from plant.sh's JSON files.

    tests/scale/plot.py --out docs/benchmarks/plant build/scale/plant-*.json

One figure per cost, a line per discovery setup (and with plant.sh --follow
apart), plant size (services) on the x axis; where several runs have the
same setup and size, the newest is plotted. Needs Debian's python3-matplotlib (deploy/install-deps.sh).
"""

import argparse
import json
import os

import matplotlib

matplotlib.use("Agg")  # no display: files only
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {"simple": ("simple discovery", "o-"), "server": ("discovery-server pair", "s--"),
         # plant.sh --follow: the clients of a cell follow only it
         "simple+f": ("simple, following", "v:"), "server+f": ("server pair, following", "^-.")}


def get(result, path):
    value = result
    for key in path:
        if value is None:
            return None
        value = value.get(key) if isinstance(value, dict) else None
    return value


# (file name, title, y label, [(label, path in a run's JSON, scale)], log y)
# A log axis where the figures span orders of magnitude (the quadratic ones).
FIGURES = [
    ("ready", "Time until every client is ready", "seconds",
     [("max", ("ready", "max_s"), 1), ("p50", ("ready", "p50_s"), 1)], False),
    ("service_cpu", "CPU per dh3-service (mean)", "% of one core",
     [("at rest", ("rest", "by_kind", "service", "cpu_pct_mean"), 1),
      ("commanding", ("commanding", "by_kind", "service", "cpu_pct_mean"), 1)], False),
    ("client_cpu", "CPU per client at rest (mean)", "% of one core",
     [("commander (py)", ("rest", "by_kind", "py-commander", "cpu_pct_mean"), 1),
      ("cell watcher (py)", ("rest", "by_kind", "py-watcher", "cpu_pct_mean"), 1),
      ("plant watcher (py)", ("rest", "by_kind", "py-plantwatcher", "cpu_pct_mean"), 1),
      ("dh3ctl events", ("rest", "by_kind", "ctl-events", "cpu_pct_mean"), 1)], False),
    ("total_cpu", "CPU of the whole plant", "% of one core",
     [("at rest", ("rest", "cpu_pct_total"), 1), ("commanding", ("commanding", "cpu_pct_total"), 1)],
     False),
    ("rss", "RSS per process (mean, at rest)", "MiB",
     [("dh3-service", ("rest", "by_kind", "service", "rss_kib_mean"), 1 / 1024),
      ("commander (py)", ("rest", "by_kind", "py-commander", "rss_kib_mean"), 1 / 1024),
      ("plant watcher (py)", ("rest", "by_kind", "py-plantwatcher", "rss_kib_mean"), 1 / 1024),
      ("dh3ctl events", ("rest", "by_kind", "ctl-events", "rss_kib_mean"), 1 / 1024)], False),
    ("bridge", "Bytes delivered by the bridge", "kB/s",
     [("rest: discovery", ("rest", "net", "dlv_disc_Bps"), 1e-3),
      ("rest: data", ("rest", "net", "dlv_data_Bps"), 1e-3),
      ("commanding: data", ("commanding", "net", "dlv_data_Bps"), 1e-3)], True),
    ("round_trip", "Register read round trip while commanding", "ms",
     [("p50", ("commanding", "commands", "read_ms_p50"), 1),
      ("p99", ("commanding", "commands", "read_ms_p99"), 1)], True),
    ("cell_watcher", "What reaches one cell's watcher at rest", "status samples/s",
     [("all cells", ("rest", "watcher", "status_all"), 1),
      ("its own cell", ("rest", "watcher", "status_cell"), 1)], False),
]


def main():
    parser = argparse.ArgumentParser(description="plots of plant.sh's JSON files")
    parser.add_argument("--out", required=True, help="directory for the PNG files")
    parser.add_argument("files", nargs="+")
    args = parser.parse_args()
    runs = {}
    for path in sorted(args.files):  # names end in a UTC stamp: later overrides earlier
        with open(path) as f:
            result = json.load(f)
        setup = result["discovery"] + ("+f" if result.get("follow") else "")
        runs[(setup, result["services"])] = result
    os.makedirs(args.out, exist_ok=True)
    hands = sorted({r["hands"] for r in runs.values()})
    sizes = sorted({s for _, s in runs})
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for name, title, ylabel, series, logy in FIGURES:
        fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=100)
        for setup, (setup_label, style) in STYLE.items():
            points = sorted((s, r) for (d, s), r in runs.items() if d == setup)
            if not points:
                continue
            for n, (label, path, scale) in enumerate(series):
                xs, ys = [], []
                for services, result in points:
                    value = get(result, path)
                    if value is not None:
                        xs.append(services)
                        ys.append(value * scale)
                if xs:
                    ax.plot(xs, ys, style, color=colors[n % len(colors)],
                            label=f"{setup_label}: {label}")
        ax.set_title(f"{title} ({'/'.join(map(str, hands))} hands per service)")
        ax.set_xlabel("services (plant size)")
        ax.set_ylabel(ylabel)
        ax.set_xscale("log", base=2)
        ax.set_xticks(sizes)
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        if name == "total_cpu":
            cores = max(get(r, ("rest", "machine", "cores")) or 0 for r in runs.values())
            if cores:
                ax.axhline(100 * cores, color="grey", linewidth=1,
                           label=f"the whole machine ({cores} cores)")
        if logy:
            ax.set_yscale("log")
        else:
            ax.set_ylim(bottom=0)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        target = os.path.join(args.out, f"plant_{name}.png")
        fig.savefig(target)
        plt.close(fig)
        print(f"plot.py: {target}")


if __name__ == "__main__":
    main()
