"""The plant: hosts as network namespaces on one Linux bridge, dh3-service hosts
with simulated hands, client hosts with client processes, and optionally a
redundant pair of Fast DDS discovery servers; what each process and the bridge
cost. Shared by plant_run.py (the benchmark) and the fault tests.

    with Plant(find_binaries(build), services=2, hands=8, discovery="server") as plant:
        plant.start_discovery_servers(); plant.start_services(); plant.wait_services()
        watcher = plant.start_watcher("c01", "cell01")
        ...

Layout (addresses link-local, one /16 on the bridge, UDP only):

    [TAG-br: bridge br0, nft counters]
      |-- sNN  TAG-sNN  169.254.1.NN   dh3-service "cellNN" (NN from 01)
      |-- cNN  TAG-cNN  169.254.2.NN+1 client processes (c00 first)
      '-- dN   TAG-dN   169.254.3.N+1  fast-discovery-server -i N (server setup)

Everything runs inside the plant's namespaces, so nothing it sends leaves
them. The bridge does no multicast snooping: with no IGMP querier on it a
snooping bridge would forget the members after 260 s and drop simple
discovery's multicast; flooding is what a plain switch does.
"""

import json
import os
import re
import shutil
import signal
import subprocess
import threading
import time

CLK_TCK = os.sysconf("SC_CLK_TCK")
DS_PORT = 11811
HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON = "/usr/bin/python3"


class Skip(Exception):
    """The plant cannot be made here: the caller exits 77 with the reason."""


class PlantError(Exception):
    pass


def run(*argv, input=None, check=True):
    result = subprocess.run([str(a) for a in argv], input=input, text=True, capture_output=True)
    if check and result.returncode != 0:
        raise PlantError(f"{' '.join(map(str, argv))}: {result.stderr.strip()}")
    return result.stdout


def require_root():
    if os.geteuid() != 0:
        raise Skip("needs root to create network namespaces")
    if shutil.which("ip") is None:
        raise Skip("iproute2 (ip) is not installed")
    if shutil.which("nft") is None:
        raise Skip("nftables (nft) is not installed: it counts the bridge's bytes by kind")


def find_binaries(build: str) -> dict:
    """dh3-service, dh3ctl and the dh3 Python package's directory in a build
    tree, wherever the tree's layout puts them."""
    found = {}
    for root, dirs, files in os.walk(build):
        dirs[:] = [d for d in dirs if d != "CMakeFiles"]
        for name in files:
            path = os.path.join(root, name)
            if name in ("dh3-service", "dh3ctl") and os.access(path, os.X_OK):
                found.setdefault(name, path)
            if name.startswith("_dh3") and name.endswith(".so") and os.path.basename(root) == "dh3":
                found.setdefault("pythonpath", os.path.dirname(root))
    missing = [n for n in ("dh3-service", "dh3ctl", "pythonpath") if n not in found]
    if missing:
        raise PlantError(f"not in the build tree {build}: {', '.join(missing)} "
                         "(the Python module needs pybind11-dev and python3-dev)")
    found["discovery-server"] = shutil.which("fast-discovery-server")
    return found


def given_binaries(service, ctl, pythonpath) -> dict:
    """The programs as ctest names them (the build targets' files)."""
    pythonpath = os.path.normpath(pythonpath)
    for path in (service, ctl):
        if not os.access(path, os.X_OK):
            raise PlantError(f"not a program: {path}")
    if not any(n.startswith("_dh3") for n in os.listdir(os.path.join(pythonpath, "dh3"))):
        raise PlantError(f"no dh3 Python module in {pythonpath}/dh3")
    return {"dh3-service": service, "dh3ctl": ctl, "pythonpath": pythonpath,
            "discovery-server": shutil.which("fast-discovery-server")}


def percentile(values, fraction):
    if not values:
        return None
    ordered = sorted(values)
    index = min(len(ordered) - 1, max(0, round(fraction * (len(ordered) - 1))))
    return ordered[index]


def machine_cpu():
    """(busy, steal, total) CPU seconds of the whole machine from /proc/stat:
    what every process used, the plant's and everybody else's."""
    with open("/proc/stat") as f:
        fields = [int(x) for x in f.readline().split()[1:]]
    user, nice, system, idle, iowait, irq, softirq, steal = fields[:8]
    busy = user + nice + system + irq + softirq
    return (busy / CLK_TCK, steal / CLK_TCK, (busy + idle + iowait + steal) / CLK_TCK)


def loadavg():
    with open("/proc/loadavg") as f:
        return [float(x) for x in f.read().split()[:3]]


class Proc:
    """A process of the plant, started in one of its namespaces."""

    def __init__(self, name, kind, host, popen, out):
        self.name, self.kind, self.host = name, kind, host
        self.popen, self.out = popen, out
        self.launched = time.time()

    @property
    def pid(self):
        return self.popen.pid

    def alive(self):
        return self.popen.poll() is None

    def stat(self):
        """(utime + stime in seconds, VmRSS in KiB), None once it has exited."""
        try:
            with open(f"/proc/{self.pid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            with open(f"/proc/{self.pid}/status") as f:
                rss = next((int(l.split()[1]) for l in f if l.startswith("VmRSS:")), 0)
        except (OSError, StopIteration):
            return None
        # Fields after the command's ")": state is [0], utime [11], stime [12].
        return ((int(fields[11]) + int(fields[12])) / CLK_TCK, rss)

    def signal(self, sig):
        if self.alive():
            try:
                os.kill(self.pid, sig)
            except ProcessLookupError:
                pass

    def lines(self):
        """The JSON lines it wrote so far (the Python clients)."""
        records = []
        try:
            with open(self.out) as f:
                for line in f:
                    if line.endswith("\n"):
                        try:
                            records.append(json.loads(line))
                        except ValueError:
                            pass
        except OSError:
            pass
        return records

    def first(self, ev):
        return next((r for r in self.lines() if r.get("ev") == ev), None)


class CtlWatcher(Proc):
    """`dh3ctl --json status --watch` or `dh3ctl events` of the whole plant:
    a thread reads its lines as they come and keeps what the plant asks about.
    Ready: every hand of the plant seen (status), the "watching" line (events,
    which dh3ctl prints once a service is ready)."""

    EVENT = re.compile(r"^(\S+/\S+/\d+)(?: \(.*?\))? ([A-Z_]+) position")

    def __init__(self, name, kind, host, popen, out, hands_expected):
        super().__init__(name, kind, host, popen, out)
        self.expected = hands_expected
        self.lock = threading.Lock()
        self.ready_t = None
        self.lines_total = 0
        self.by_cell = {}
        self.online = {}
        self.read_at = {}
        self.transitions = []  # (t, hand, "online"|"offline")
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self):
        with open(self.out, "w") as log:
            for line in self.popen.stdout:
                now = time.time()
                with self.lock:
                    self.lines_total += 1
                    if self.kind == "ctl-status":
                        self._status(now, line)
                    else:
                        self._event(now, line)
                if self.lines_total <= 2000:  # the start is what tells why it failed
                    log.write(f"{now:.3f} {line}")

    def _status(self, now, line):
        try:
            s = json.loads(line)
        except ValueError:
            return
        hand = s.get("hand")
        if hand is None:
            return
        cell = s.get("service", "")
        self.by_cell[cell] = self.by_cell.get(cell, 0) + 1
        was = self.online.get(hand)
        self.online[hand] = bool(s.get("online"))
        self.read_at[hand] = int(s.get("read_at_ns", 0))
        if was is not None and was != self.online[hand]:
            self.transitions.append((now, hand, "online" if self.online[hand] else "offline"))
        if self.ready_t is None and len(self.online) >= self.expected:
            self.ready_t = now

    def _event(self, now, line):
        if line.startswith("watching events"):
            self.ready_t = self.ready_t or now
            return
        m = self.EVENT.match(line)
        if not m:
            return
        hand, kind = m.groups()
        cell = hand.split("/")[0]
        self.by_cell[cell] = self.by_cell.get(cell, 0) + 1
        if kind in ("ONLINE", "OFFLINE"):
            self.online[hand] = kind == "ONLINE"
            self.transitions.append((now, hand, kind.lower()))

    def snapshot(self):
        with self.lock:
            return {"lines": self.lines_total, "by_cell": dict(self.by_cell),
                    "online": dict(self.online), "read_at": dict(self.read_at)}


class Plant:
    def __init__(self, bins, services=2, hands=8, client_hosts=2, discovery="simple",
                 domain=0, workdir=None, tag=None, objects=True, log=print,
                 service_log_level="info"):
        if discovery not in ("simple", "server"):
            raise ValueError(discovery)
        require_root()
        if discovery == "server" and not bins.get("discovery-server"):
            raise Skip("fast-discovery-server (package fastdds-tools) is not installed")
        self.bins, self.services, self.hands = bins, services, hands
        self.client_hosts, self.discovery, self.domain = client_hosts, discovery, domain
        self.objects, self.log = objects, log
        self.service_log_level = service_log_level
        self.tag = tag or os.environ.get("PLANT_TAG") or f"pl{os.getpid() % 100000}"
        self.workdir = workdir or f"/tmp/{self.tag}"
        os.makedirs(self.workdir, exist_ok=True)
        self.hosts = {}    # short name -> address
        self.procs = []
        self.service_procs = {}  # cell index -> Proc
        self.ds_procs = {}
        self.bridge = self.ns("br")
        self.made = []

    # ---- names and addresses
    def ns(self, short):
        return f"{self.tag}-{short}"

    @staticmethod
    def cell(i):
        return f"cell{i:02d}"

    def ds_addresses(self):
        return [f"169.254.3.{k + 1}" for k in range(2)] if self.discovery == "server" else []

    def dds_args(self, host):
        """The DDS options every participant of the plant gets on `host`."""
        args = ["--domain", str(self.domain), "--interface", self.hosts[host], "--udp-only"]
        for addr in self.ds_addresses():
            args += ["--discovery-server", f"{addr}:{DS_PORT}"]
        return args

    # ---- the network
    def __enter__(self):
        try:
            self.build_network()
        except BaseException:
            self.teardown()
            raise
        return self

    def __exit__(self, *exc):
        self.teardown()

    def build_network(self):
        self.make_room_in_neighbour_table()
        result = subprocess.run(["ip", "netns", "add", self.bridge], capture_output=True, text=True)
        if result.returncode != 0:
            raise Skip(f"ip netns add failed: {result.stderr.strip()}")
        self.made.append(self.bridge)
        run("ip", "-n", self.bridge, "link", "set", "lo", "up")
        run("ip", "-n", self.bridge, "link", "add", "br0", "type", "bridge",
            "mcast_snooping", "0", "stp_state", "0")
        run("ip", "-n", self.bridge, "link", "set", "br0", "up")
        self.counters_up()
        for i in range(1, self.services + 1):
            self.add_host(f"s{i:02d}", f"169.254.1.{i}")
        for i in range(self.client_hosts + 1):
            self.add_host(f"c{i:02d}", f"169.254.2.{i + 1}")
        for k, addr in enumerate(self.ds_addresses()):
            self.add_host(f"d{k}", addr)

    # The kernel's ARP table is one for all namespaces, and its limits (the
    # gc_thresh sysctls, 128/512/1024 by default) are the initial namespace's.
    # Every host of the plant keeps an entry for each host it talks to, so
    # 50 hosts need about 2,500: over the limit, the kernel drops what a host
    # sends to a peer it has no entry for ("neighbor table overflow" in
    # dmesg, the socket's send reported as done). A real plant has a table per
    # machine; this one raises the shared limits for its run, and puts back
    # what it raised.
    NEIGH = "/proc/sys/net/ipv4/neigh/default/gc_thresh{}"

    def make_room_in_neighbour_table(self):
        self.neigh_raised = {}
        hosts = self.services + self.client_hosts + 1 + len(self.ds_addresses()) + 1
        wanted = {1: hosts * hosts, 2: 2 * hosts * hosts, 3: 4 * hosts * hosts}
        for k in (3, 2, 1):  # raise the hard limit first: thresh1 <= thresh2 <= thresh3
            path = self.NEIGH.format(k)
            try:
                with open(path) as f:
                    now = int(f.read())
                if now < wanted[k]:
                    with open(path, "w") as f:
                        f.write(str(wanted[k]))
                    self.neigh_raised[k] = now
            except OSError as e:
                self.log(f"   cannot raise {path} ({e}): a plant of {hosts} hosts may "
                         "overflow the kernel's neighbour table")
                return
        if self.neigh_raised:
            self.log(f"   kernel neighbour table limits raised for {hosts} hosts: "
                     + ", ".join(f"gc_thresh{k} {v} -> {wanted[k]}"
                                 for k, v in sorted(self.neigh_raised.items())))

    def restore_neighbour_table(self):
        for k in (1, 2, 3):  # lower thresh1 first
            if k in getattr(self, "neigh_raised", {}):
                try:
                    with open(self.NEIGH.format(k), "w") as f:
                        f.write(str(self.neigh_raised[k]))
                except OSError:
                    pass
        self.neigh_raised = {}

    def add_host(self, short, addr):
        ns = self.ns(short)
        run("ip", "netns", "add", ns)
        self.made.append(ns)
        run("ip", "-n", ns, "link", "set", "lo", "up")
        # IPv4 only: IPv6's neighbour and router chatter would only blur the counts.
        for key in ("all", "default"):
            run("ip", "netns", "exec", ns, "sysctl", "-qw", f"net.ipv6.conf.{key}.disable_ipv6=1")
        # eth0 in the host, its peer (named as the host) a port of the bridge.
        run("ip", "link", "add", "eth0", "netns", ns, "type", "veth", "peer", "name", short,
            "netns", self.bridge)
        run("ip", "-n", ns, "addr", "add", f"{addr}/16", "dev", "eth0")
        run("ip", "-n", ns, "link", "set", "eth0", "up", "multicast", "on")
        run("ip", "-n", self.bridge, "link", "set", short, "master", "br0", "up")
        self.hosts[short] = addr

    def set_link(self, short, up: bool):
        """The host's cable: its port on the bridge down or up."""
        run("ip", "-n", self.bridge, "link", "set", short, "up" if up else "down")

    def counters_up(self):
        """nft counters on the bridge: bytes entering it (sent by a host) and
        leaving it (delivered to a host: a flooded multicast counts once per
        port), split into discovery and data by UDP destination port. Fast DDS
        ports for domain d: 7400+250d discovery multicast, +1 data multicast,
        +10+2p discovery unicast, +11+2p data unicast of participant p of a
        host; the discovery servers listen on 11811. IP fragments after the
        first carry no port and count as "other"."""
        base = 7400 + 250 * self.domain
        disc = [base, DS_PORT] + [base + 10 + 2 * p for p in range(120)]
        data = [base + 1] + [base + 11 + 2 * p for p in range(120)]
        chains = []
        for hook, prefix in (("prerouting", "sent"), ("forward", "dlv")):
            chains.append(f"""
  chain {prefix} {{
    type filter hook {hook} priority 0; policy accept;
    udp dport @disc counter name {prefix}_disc accept
    udp dport @data counter name {prefix}_data accept
    counter name {prefix}_other
  }}""")
        counters = "".join(f"  counter {p}_{k} {{}}\n" for p in ("sent", "dlv")
                           for k in ("disc", "data", "other"))
        ruleset = f"""table bridge plant {{
{counters}  set disc {{ type inet_service; elements = {{ {', '.join(map(str, disc))} }} }}
  set data {{ type inet_service; elements = {{ {', '.join(map(str, data))} }} }}
{''.join(chains)}
}}
"""
        run("ip", "netns", "exec", self.bridge, "nft", "-f", "-", input=ruleset)

    def read_counters(self):
        """{"ports": {port: {rx, tx bytes and packets}}, "nft": {name: bytes}}:
        a port's rx is what its host sent, its tx what the host was delivered."""
        links = json.loads(run("ip", "-n", self.bridge, "-s", "-j", "link", "show"))
        ports = {}
        for link in links:
            if link["ifname"] in self.hosts:
                s = link["stats64"]
                ports[link["ifname"]] = {"rx": s["rx"]["bytes"], "tx": s["tx"]["bytes"],
                                         "rx_packets": s["rx"]["packets"],
                                         "tx_packets": s["tx"]["packets"]}
        listing = json.loads(run("ip", "netns", "exec", self.bridge, "nft", "-j", "list",
                                 "counters", "table", "bridge", "plant"))
        nft = {}
        for item in listing.get("nftables", []):
            if "counter" in item:
                nft[item["counter"]["name"]] = item["counter"]["bytes"]
        return {"ports": ports, "nft": nft}

    # ---- processes
    def spawn(self, name, kind, host, argv, env=None, cls=Proc, pipe=False, **extra):
        out = os.path.join(self.workdir, f"{name}.log")
        # `ip netns exec` execs the program: the Popen's pid is the program's.
        full = ["ip", "netns", "exec", self.ns(host)] + [str(a) for a in argv]
        if pipe:
            popen = subprocess.Popen(full, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                     stderr=open(out + ".err", "w"), text=True, env=env,
                                     start_new_session=True)
        else:
            popen = subprocess.Popen(full, stdin=subprocess.DEVNULL,
                                     stdout=open(out + ".stdout", "w"),
                                     stderr=subprocess.STDOUT, env=env, start_new_session=True)
        proc = cls(name, kind, host, popen, out, **extra)
        self.procs.append(proc)
        return proc

    def start_discovery_servers(self):
        for k, addr in enumerate(self.ds_addresses()):
            self.start_discovery_server(k)

    def start_discovery_server(self, k):
        addr = self.ds_addresses()[k]
        proc = self.spawn(f"ds{k}", "discovery-server", f"d{k}",
                          [self.bins["discovery-server"], "-i", k, "-l", addr, "-p", DS_PORT])
        self.ds_procs[k] = proc
        return proc

    def service_config(self, i):
        path = os.path.join(self.workdir, f"{self.cell(i)}.yaml")
        hands = "".join(f"      - {{id: {h}{', object: 40' if self.objects else ''}}}\n"
                        for h in range(1, self.hands + 1))
        # The hands answer at once and take no pause between frames, as in
        # bench_cell: a round trip is then the network's and the processes',
        # not the hand's. Status polling keeps its defaults (what a plant at
        # rest costs).
        with open(path, "w") as f:
            f.write("buses:\n"
                    "  - name: bus0\n"
                    "    spec: sim\n"
                    "    command_interval_ms: 0\n"
                    "    sim: {reply_delay_ms: 0}\n"
                    "    hands:\n" + hands)
        return path

    def start_services(self):
        for i in range(1, self.services + 1):
            self.start_service(i)

    def start_service(self, i):
        host = f"s{i:02d}"
        argv = [self.bins["dh3-service"], "--config", self.service_config(i), "--name", self.cell(i),
                "--log-level", self.service_log_level] + self.dds_args(host)
        # A restarted service appends to the same log.
        name = self.cell(i) if i not in self.service_procs else f"{self.cell(i)}-r{time.time():.0f}"
        proc = self.spawn(name, "service", host, argv)
        self.service_procs[i] = proc
        return proc

    def service_up(self, i):
        """True once the service's participant is on the domain (its log says so)."""
        proc = self.service_procs[i]
        try:
            with open(proc.out + ".stdout") as f:
                return " on DDS domain " in f.read()
        except OSError:
            return False

    def wait_services(self, deadline_s=60.0):
        end = time.time() + deadline_s
        while time.time() < end:
            dead = [p.name for p in self.service_procs.values() if not p.alive()]
            if dead:
                raise PlantError(f"service exited: {', '.join(dead)}")
            if all(self.service_up(i) for i in self.service_procs):
                return
            time.sleep(0.1)
        raise PlantError("services not up within the deadline")

    def python_env(self):
        env = dict(os.environ)
        env["PYTHONPATH"] = self.bins["pythonpath"]
        env["PYTHONDONTWRITEBYTECODE"] = "1"
        return env

    def start_python(self, role, host, name, *args):
        argv = [PYTHON, os.path.join(HERE, "plant_client.py"), role,
                "--out", os.path.join(self.workdir, f"{name}.jsonl")] + list(args) + self.dds_args(host)
        proc = self.spawn(name, f"py-{role}", host, argv, env=self.python_env())
        proc.out = os.path.join(self.workdir, f"{name}.jsonl")
        return proc

    # Whether the commanders, one-shot clients and cell watchers follow their
    # cell (dh3.Client(follow=...)): the services then send each only its
    # cell's statuses and events. The plant watchers follow everything.
    follow = False

    def follow_args(self, cell="all"):
        return ["--follow"] if self.follow and cell != "all" else []

    def start_commander(self, host, hand_spec, name=None, reads=5):
        return self.start_python("commander", host, name or f"cmd-{hand_spec.replace('/', '-')}",
                                 "--hand", hand_spec, "--reads", reads,
                                 *self.follow_args(hand_spec))

    def start_oneshot(self, host, hand_spec, name, reads=2, linger=0.0):
        return self.start_python("oneshot", host, name, "--hand", hand_spec, "--reads", reads,
                                 "--linger", linger, *self.follow_args(hand_spec))

    def start_watcher(self, host, cell, name=None):
        """A Python watcher of one cell, or of the whole plant (cell "all")."""
        hands = self.hands * self.services if cell == "all" else self.hands
        proc = self.start_python("watcher", host, name or f"watch-{cell}-{host}",
                                 "--cell", cell, "--hands", hands, *self.follow_args(cell))
        if cell == "all":
            proc.kind = "py-plantwatcher"
        return proc

    def start_ctl_watcher(self, host, what, name):
        """what: "status" (dh3ctl --json status --watch) or "events" (dh3ctl events)."""
        base = [self.bins["dh3ctl"]] + self.dds_args(host) + ["--timeout", "600"]
        argv = base + (["--json", "status", "--watch"] if what == "status" else ["events"])
        return self.spawn(name, f"ctl-{what}", host, argv, cls=CtlWatcher, pipe=True,
                          hands_expected=self.hands * self.services)

    def start_ctl(self, host, name, *command):
        """A one-shot dh3ctl (its outcome is its exit status)."""
        return self.spawn(name, "ctl-oneshot", host,
                          [self.bins["dh3ctl"]] + self.dds_args(host) + list(command))

    # ---- what the clients say
    @staticmethod
    def ready_time(proc):
        if isinstance(proc, CtlWatcher):
            return proc.ready_t
        record = proc.first("ready")
        return record["t"] if record else None

    def mark(self, watchers, deadline_s=10.0):
        """Asks every Python watcher for its counts; {name: mark record}."""
        before = {w.name: sum(1 for r in w.lines() if r.get("ev") == "mark") for w in watchers}
        for w in watchers:
            w.signal(signal.SIGUSR1)
        marks = {}
        end = time.time() + deadline_s
        while time.time() < end and len(marks) < len(watchers):
            for w in watchers:
                if w.name in marks:
                    continue
                found = [r for r in w.lines() if r.get("ev") == "mark"]
                if len(found) > before[w.name]:
                    marks[w.name] = found[-1]
            time.sleep(0.05)
        return marks

    # ---- the end
    def stop_procs(self, procs, grace_s=10.0):
        for p in procs:
            p.signal(signal.SIGTERM)
        end = time.time() + grace_s
        for p in procs:
            try:
                p.popen.wait(timeout=max(0.1, end - time.time()))
            except subprocess.TimeoutExpired:
                p.signal(signal.SIGKILL)
                p.popen.wait()

    def teardown(self):
        try:
            self.stop_procs([p for p in self.procs if p.alive()])
        finally:
            for ns in reversed(self.made):
                # Whatever still runs in a namespace is the plant's.
                pids = run("ip", "netns", "pids", ns, check=False).split()
                for pid in pids:
                    try:
                        os.kill(int(pid), signal.SIGKILL)
                    except (ProcessLookupError, ValueError):
                        pass
                run("ip", "netns", "del", ns, check=False)
            self.made = []
            self.restore_neighbour_table()
