#!/usr/bin/env python3
"""Checks deploy/'s container, Compose and Kubernetes files without running them.

    check_manifests.py SOURCE_DIR CHECK_CONFIG [--print-programs]

- every YAML file under deploy/ parses;
- every file they (and the Dockerfile) name exists;
- every dh3-service configuration they carry (files, ConfigMaps) is accepted
  by dh3-service's own parser (CHECK_CONFIG, tests/deploy/check_config.cpp);
- what they say about each other agrees: the health check's service name and
  domain are the config's, the discovery server's address is where the server
  listens, the image's user is the manifests' user, containers are UDP only;
- a file that deploys dh3-service without DDS Security says so in its
  header and points at docs/security.md, which names the file;
- the hot-standby pairs: the Compose file's service and standby carry one
  configuration of role auto whose buses are the box that the Compose file
  shares (dh3-sim --shared at that address); deploy/config/dh3-pair.yaml,
  the pair on two cell PCs, is role auto on a real bus and a NIC, and the
  Debian package installs it;
- with --print-programs, prints "program NAME" for every program the
  Dockerfile, the Compose file and the manifests run (the container tests
  check that the image has each).

Prints one line per problem and exits 1 if there is any.
"""
import ipaddress
import os
import re
import shlex
import subprocess
import sys
import tempfile

import yaml

problems = []


def problem(text):
    problems.append(text)
    print("PROBLEM: " + text)


def load_all(path):
    with open(path, encoding="utf-8") as f:
        return [d for d in yaml.safe_load_all(f) if d is not None]


def main():
    args = sys.argv[1:]
    print_programs = "--print-programs" in args
    if print_programs:
        args.remove("--print-programs")
    if len(args) != 2:
        print(__doc__)
        return 2
    src, check_config = args
    deploy = os.path.join(src, "deploy")

    # 1. Every YAML file parses.
    yaml_files = []
    for root, _, files in os.walk(deploy):
        for name in files:
            if name.endswith((".yaml", ".yml")):
                yaml_files.append(os.path.join(root, name))
    docs = {}
    for path in sorted(yaml_files):
        try:
            docs[path] = load_all(path)
        except yaml.YAMLError as error:
            problem(f"{path}: not valid YAML: {error}")
    print(f"parsed {len(docs)} YAML files")

    configs = {}  # label -> YAML text of a dh3-service config
    programs = set()  # programs the image must provide

    # deploy/packages/dh3.yaml: the Debian package's /etc/dh3/dh3.yaml.
    for folder in ("config", "packages"):
        for path in sorted(os.listdir(os.path.join(deploy, folder))):
            if path.endswith(".yaml"):
                full = os.path.join(deploy, folder, path)
                with open(full, encoding="utf-8") as f:
                    configs[full] = f.read()

    dockerfile_uid = check_dockerfile(src, programs)
    check_compose(src, docs, configs, programs)
    check_kubernetes(src, docs, configs, programs, dockerfile_uid)
    check_docs(src)
    check_pair_config(src)
    check_exposure(src)
    check_configs(check_config, configs)
    if print_programs:
        for program in sorted(programs):
            print(f"program {program}")

    if problems:
        print(f"{len(problems)} problem(s)")
        return 1
    print("manifests: no problems")
    return 0


# The files that run dh3-service on a network other machines or containers
# share: the image (its built-in config serves every interface), Compose and
# the two Kubernetes Deployments.
DEPLOYING_FILES = ("deploy/container/Dockerfile", "deploy/container/compose.yaml",
                   "deploy/kubernetes/dh3-service.yaml",
                   "deploy/kubernetes/dh3-service-hostnetwork.yaml")


def check_exposure(src):
    """Each deploying file has DDS Security in the config it carries, or its
    header says plainly that it has none and where what that exposes is told."""
    with open(os.path.join(src, "docs/security.md"), encoding="utf-8") as f:
        page = f.read()
    for rel in DEPLOYING_FILES:
        with open(os.path.join(src, rel), encoding="utf-8") as f:
            text = f.read()
        if re.search(r"^\s+security:\s*$", text, re.MULTILINE) or "--security-dir" in text:
            continue
        comments = " ".join(l.lstrip("# ").strip() for l in text.splitlines()
                            if l.lstrip().startswith("#"))
        if "Without DDS Security" not in comments or "docs/security.md" not in comments:
            problem(f"{rel}: deploys dh3-service without DDS Security and its comments do not "
                    "say so (\"Without DDS Security: ...\", docs/security.md)")
        if os.path.basename(rel) not in page:
            problem(f"docs/security.md does not say what {rel} exposes")
    print(f"exposure: {len(DEPLOYING_FILES)} deploying files state theirs")


def config_of(text):
    return yaml.safe_load(text) or {}


def check_dockerfile(src, programs):
    path = os.path.join(src, "deploy/container/Dockerfile")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    # Join continuation lines, drop comments.
    logical = re.sub(r"\\\n", " ", "\n".join(l for l in text.splitlines() if not l.lstrip().startswith("#")))
    lines = [l.strip() for l in logical.splitlines() if l.strip()]
    stages = []
    uid = None
    for line in lines:
        word, _, rest = line.partition(" ")
        word = word.upper()
        if word == "FROM":
            image = rest.split()[0]
            stages.append(image)
            if not image.startswith("debian:bookworm"):
                problem(f"Dockerfile: stage from {image}, not Debian bookworm")
        elif word == "COPY":
            parts = shlex.split(rest)
            if any(p.startswith("--from") for p in parts):
                continue
            for source in parts[:-1]:
                if not os.path.exists(os.path.join(src, source)):
                    problem(f"Dockerfile: COPY {source}: no such file in the source tree")
        elif word == "USER":
            user = rest.split(":")[0]
            if not user.isdigit() or int(user) == 0:
                problem(f"Dockerfile: USER {rest} is not a numeric non-root user")
            else:
                uid = int(user)
        elif word in ("ENTRYPOINT", "HEALTHCHECK"):
            exec_form = re.search(r"\[(.*)\]", rest)
            if not exec_form:
                problem(f"Dockerfile: {word} is not in exec form")
                continue
            first = yaml.safe_load("[" + exec_form.group(1) + "]")[0]
            programs.add(first)
    if len(stages) != 2:
        problem(f"Dockerfile: {len(stages)} stages, expected build and runtime")
    runs = [l for l in lines if l.upper().startswith("RUN ")]
    for needed in ("deploy/install-deps.sh", "deploy/container/build-in-image.sh",
                   "install-deps.sh --runtime"):
        if not any(needed in r for r in runs):
            problem(f"Dockerfile: no RUN step runs {needed}")
    if not any(l.upper().startswith("HEALTHCHECK ") for l in lines):
        problem("Dockerfile: no HEALTHCHECK")
    print(f"Dockerfile: stages {stages}, user {uid}")
    return uid


def check_compose(src, docs, configs, programs):
    path = os.path.join(src, "deploy/container/compose.yaml")
    base = os.path.dirname(path)
    compose = docs.get(path, [{}])[0]
    services = compose.get("services", {})
    for name in ("discovery", "service", "pick"):
        if name not in services:
            problem(f"compose: no service '{name}'")
    subnets = [ipaddress.ip_network(c["subnet"])
               for n in compose.get("networks", {}).values()
               for c in (n or {}).get("ipam", {}).get("config", [])]
    addresses = {}
    for name, svc in services.items():
        build = svc.get("build")
        if build:
            context = os.path.normpath(os.path.join(base, build.get("context", ".")))
            if not os.path.isdir(context):
                problem(f"compose {name}: build context {context} missing")
            if not os.path.isfile(os.path.join(context, build.get("dockerfile", "Dockerfile"))):
                problem(f"compose {name}: Dockerfile {build.get('dockerfile')} missing")
        for volume in svc.get("volumes", []):
            # "${VAR:-default}": Compose's interpolation, checked with the default.
            volume = re.sub(r"\$\{[A-Za-z0-9_]+:-([^}]*)\}", r"\1", volume)
            host, target = volume.split(":")[0:2]
            host_path = os.path.normpath(os.path.join(base, host))
            if not os.path.exists(host_path):
                problem(f"compose {name}: volume source {host} missing")
            elif target == "/etc/dh3/dh3.yaml":
                with open(host_path, encoding="utf-8") as f:
                    configs[f"compose {name}: {host}"] = f.read()
                svc["_config"] = config_of(configs[f"compose {name}: {host}"])
        for net in (svc.get("networks") or {}).values():
            if net and "ipv4_address" in net:
                address = ipaddress.ip_address(net["ipv4_address"])
                addresses[name] = address
                if not any(address in s for s in subnets):
                    problem(f"compose {name}: {address} is outside the network's subnets")
        entry = svc.get("entrypoint")
        programs.add(entry[0] if entry else "dh3-service")

    discovery = services.get("discovery", {})
    command = discovery.get("command", [])
    listen = command[command.index("-l") + 1] if "-l" in command else None
    port = command[command.index("-p") + 1] if "-p" in command else "11811"
    if listen != str(addresses.get("discovery")):
        problem(f"compose discovery: listens on {listen}, its address is {addresses.get('discovery')}")
    for name, svc in services.items():
        env = svc.get("environment", {})
        # The discovery server, and dh3-sim's box, which is no DDS participant.
        if name == "discovery" or (svc.get("entrypoint") or [""])[0] == "dh3-sim":
            continue
        if env.get("ROS_DISCOVERY_SERVER") != f"{listen}:{port}":
            problem(f"compose {name}: ROS_DISCOVERY_SERVER is {env.get('ROS_DISCOVERY_SERVER')},"
                    f" the server listens on {listen}:{port}")
    service = services.get("service", {})
    config = service.get("_config", {})
    if not config:
        problem("compose service: no config mounted at /etc/dh3/dh3.yaml")
    env = service.get("environment", {})
    if str(env.get("DH3_SERVICE")) != str(config.get("name")) or \
            str(env.get("DH3_DOMAIN")) != str(config.get("domain", 0)):
        problem("compose service: DH3_SERVICE/DH3_DOMAIN differ from the config's name/domain")
    dds = config.get("dds", {})
    if dds.get("udp_only") is not True or dds.get("interfaces") != ["*"]:
        problem("compose service: the config is not UDP only on every interface")
    pick = services.get("pick", {})
    pick_command = pick.get("command", [])
    if "--udp-only" not in pick_command:
        problem("compose pick: not --udp-only")
    hand = pick_command[pick_command.index("--hand") + 1] if "--hand" in pick_command else ""
    if hand.split("/")[0] != config.get("name"):
        problem(f"compose pick: hand {hand} is not on service {config.get('name')}")
    check_compose_pair(services, addresses)
    print(f"compose: services {sorted(services)}")


def listen_address(command):
    """HOST:PORT that a dh3-sim command line listens on."""
    return command[command.index("--listen") + 1] if "--listen" in command else None


def check_compose_pair(services, addresses):
    """service and standby are one pair on a box that the Compose file shares."""
    service, standby = services.get("service", {}), services.get("standby")
    if standby is None:
        problem("compose: no service 'standby' (the hot-standby pair's second member)")
        return
    config = service.get("_config", {})
    if standby.get("_config") != config:
        problem("compose standby: its config is not the service's")
    if config.get("role") != "auto":
        problem(f"compose service: role {config.get('role')!r}, a pair whose members run alike "
                "needs role auto")
    if standby.get("command") != service.get("command"):
        problem("compose standby: its command line is not the service's")
    if (standby.get("environment") or {}).get("DH3_SERVICE") != \
            (service.get("environment") or {}).get("DH3_SERVICE"):
        problem("compose standby: DH3_SERVICE differs from the service's")
    condition = (standby.get("depends_on") or {}).get("service", {})
    if not isinstance(condition, dict) or condition.get("condition") != "service_healthy":
        problem("compose standby: does not wait for service to serve (service_healthy)")
    shared = {}
    for name, svc in services.items():
        command = svc.get("command") or []
        if (svc.get("entrypoint") or [""])[0] == "dh3-sim" and "--shared" in command:
            shared[listen_address(command)] = name
    for bus in config.get("buses", []):
        spec = bus.get("spec", "")
        where = spec[len("tcp:"):] if spec.startswith("tcp:") else None
        box = shared.get(where)
        if box is None:
            problem(f"compose pair: bus {bus.get('name')} ({spec}) is no box that the Compose file "
                    f"shares (dh3-sim --shared --listen): {sorted(shared)}")
        elif where.split(":")[0] != str(addresses.get(box)):
            problem(f"compose {box}: listens on {where}, its address is {addresses.get(box)}")
        elif box not in (service.get("depends_on") or []):
            problem(f"compose service: does not depend on its box {box}")


def check_pair_config(src):
    """The pair on two cell PCs: role auto, a real bus, a NIC, and packaged."""
    path = os.path.join(src, "deploy/config/dh3-pair.yaml")
    with open(path, encoding="utf-8") as f:
        config = config_of(f.read())
    if config.get("role") != "auto":
        problem(f"deploy/config/dh3-pair.yaml: role {config.get('role')!r}, not auto")
    for bus in config.get("buses", []):
        if bus.get("spec", "").startswith("sim"):
            problem(f"deploy/config/dh3-pair.yaml: bus {bus.get('name')} is simulated in-process")
        if not bus.get("hands"):
            problem(f"deploy/config/dh3-pair.yaml: bus {bus.get('name')} lists no hands (the "
                    "standby's fence needs the active member's polls of listed hands)")
    if not config.get("dds", {}).get("interfaces"):
        problem("deploy/config/dh3-pair.yaml: no dds.interfaces: the other PC cannot reach it")
    with open(os.path.join(src, "deploy/packages/debian/rules"), encoding="utf-8") as f:
        rules = f.read()
    with open(os.path.join(src, "deploy/packages/debian/dh3-service.install"),
              encoding="utf-8") as f:
        installed = f.read()
    if "deploy/config/dh3-pair.yaml" not in rules or \
            "usr/share/doc/dh3-service/examples/pair.yaml" not in installed:
        problem("deploy/packages: the package does not install deploy/config/dh3-pair.yaml as "
                "examples/pair.yaml")
    print("pair: deploy/config/dh3-pair.yaml checked")


def check_kubernetes(src, docs, configs, programs, uid):
    kdir = os.path.join(src, "deploy/kubernetes")
    kust = docs.get(os.path.join(kdir, "kustomization.yaml"), [{}])[0]
    for resource in kust.get("resources", []):
        if not os.path.isfile(os.path.join(kdir, resource)):
            problem(f"kustomization: resource {resource} missing")
    image_names = {i.get("name") for i in kust.get("images", [])}
    objects = [d for p, ds in docs.items() if p.startswith(kdir) and "kustomization" not in p
               for d in ds]
    by_kind = {}
    for o in objects:
        if "kind" not in o or "apiVersion" not in o or "name" not in o.get("metadata", {}):
            problem(f"kubernetes: an object without kind, apiVersion or metadata.name: {o}")
            continue
        by_kind.setdefault(o["kind"], {})[o["metadata"]["name"]] = o
    config_maps = by_kind.get("ConfigMap", {})
    services = by_kind.get("Service", {})
    for name, cm in config_maps.items():
        if "dh3.yaml" in cm.get("data", {}):
            configs[f"ConfigMap {name}"] = cm["data"]["dh3.yaml"]
    for name, deployment in by_kind.get("Deployment", {}).items():
        spec = deployment["spec"]["template"]["spec"]
        labels = deployment["spec"]["template"]["metadata"]["labels"]
        if deployment["spec"]["selector"]["matchLabels"].items() - labels.items():
            problem(f"Deployment {name}: selector does not match the pod's labels")
        security = spec.get("securityContext", {})
        if security.get("runAsNonRoot") is not True or security.get("runAsUser") != uid:
            problem(f"Deployment {name}: not runAsNonRoot with the image's user {uid}")
        volumes = {v["name"]: v for v in spec.get("volumes", [])}
        for container in spec["containers"]:
            where = f"Deployment {name} container {container['name']}"
            if container.get("image") not in image_names:
                problem(f"{where}: image {container.get('image')} is not the kustomization's")
            resources = container.get("resources", {})
            if not resources.get("requests") or not resources.get("limits"):
                problem(f"{where}: no resource requests and limits")
            programs.add((container.get("command") or ["dh3-service"])[0])
            env = {e["name"]: e.get("value") for e in container.get("env", [])}
            config = None
            for mount in container.get("volumeMounts", []):
                volume = volumes.get(mount["name"])
                if volume is None:
                    problem(f"{where}: mounts volume {mount['name']}, which the pod lacks")
                    continue
                cm_name = volume.get("configMap", {}).get("name")
                if cm_name is None:
                    continue
                if cm_name not in config_maps:
                    problem(f"{where}: ConfigMap {cm_name} is not defined")
                elif mount["mountPath"] == "/etc/dh3":
                    config = config_of(config_maps[cm_name]["data"].get("dh3.yaml", ""))
            if (container.get("command") or ["dh3-service"])[0] != "dh3-service":
                continue
            if config is None:
                problem(f"{where}: no ConfigMap with dh3.yaml mounted at /etc/dh3")
                continue
            for probe in ("livenessProbe", "readinessProbe"):
                command = container.get(probe, {}).get("exec", {}).get("command")
                if not command:
                    problem(f"{where}: no {probe}")
                else:
                    programs.add(command[0])
            if str(env.get("DH3_SERVICE")) != str(config.get("name")) or \
                    str(env.get("DH3_DOMAIN")) != str(config.get("domain", 0)):
                problem(f"{where}: DH3_SERVICE/DH3_DOMAIN differ from the config's name/domain")
            if config.get("dds", {}).get("udp_only") is not True:
                problem(f"{where}: the config is not UDP only (pods never share /dev/shm)")
            server = env.get("ROS_DISCOVERY_SERVER")
            if server:
                host, _, port = server.partition(":")
                parts = host.split(".")
                svc = services.get(parts[0])
                if svc is None or parts[1:3] != [svc["metadata"].get("namespace"), "svc"]:
                    problem(f"{where}: ROS_DISCOVERY_SERVER {server} names no Service here")
                elif int(port) not in [p["port"] for p in svc["spec"]["ports"]]:
                    problem(f"{where}: ROS_DISCOVERY_SERVER port {port} is not the Service's")
            elif not spec.get("hostNetwork"):
                problem(f"{where}: neither a discovery server nor hostNetwork")
            specs = [b.get("spec", "") for b in config.get("buses", [])]
            if any(s.startswith("socketcan:") for s in specs) and not spec.get("hostNetwork"):
                problem(f"{where}: a SocketCAN bus needs hostNetwork (CAN interfaces are netdevs)")
            if spec.get("hostNetwork") and spec.get("dnsPolicy") != "ClusterFirstWithHostNet":
                problem(f"{where}: hostNetwork without dnsPolicy ClusterFirstWithHostNet")
    check_network_policies(by_kind)
    for name, svc in services.items():
        selector = svc["spec"].get("selector", {})
        if not any(selector.items() <= d["spec"]["template"]["metadata"]["labels"].items()
                   for d in by_kind.get("Deployment", {}).values()):
            problem(f"Service {name}: selects no Deployment's pods")
    print(f"kubernetes: {sum(len(v) for v in by_kind.values())} objects")


def check_network_policies(by_kind):
    """Every Deployment on the pod network has its pods held by a NetworkPolicy
    on ingress that admits no one from everywhere (each rule names whom it
    admits), and a port a policy names is a port of a pod it holds."""
    policies = {n: p for n, p in by_kind.get("NetworkPolicy", {}).items()
                if "Ingress" in p["spec"].get("policyTypes", [])}
    held_ports = {n: set() for n in policies}
    for name, deployment in by_kind.get("Deployment", {}).items():
        template = deployment["spec"]["template"]
        if template["spec"].get("hostNetwork"):
            continue  # on the node's network: no NetworkPolicy holds it
        labels = template["metadata"]["labels"]
        holding = [n for n, p in policies.items()
                   if p["metadata"].get("namespace") == deployment["metadata"].get("namespace")
                   and p["spec"]["podSelector"].get("matchLabels", {}).items() <= labels.items()]
        if not holding:
            problem(f"Deployment {name}: no NetworkPolicy limits who reaches its pods")
        for n in holding:
            held_ports[n] |= {port.get("name") for c in template["spec"]["containers"]
                              for port in c.get("ports", [])}
    for name, policy in policies.items():
        for rule in policy["spec"].get("ingress", []):
            if not rule.get("from"):
                problem(f"NetworkPolicy {name}: an ingress rule admits every source")
            for port in rule.get("ports", []):
                if isinstance(port.get("port"), str) and port["port"] not in held_ports[name]:
                    problem(f"NetworkPolicy {name}: port {port['port']} is no port of its pods")
    print(f"network policies: {len(policies)}")


def check_docs(src):
    """Every deploy/, tests/ or idl/ path the README and docs/ name exists."""
    if not os.path.isfile(os.path.join(src, "README.md")):
        problem("README.md missing")
        return
    operations = os.path.join(src, "docs", "operations.md")
    if not os.path.isfile(operations) or "## Deployment" not in open(operations, encoding="utf-8").read():
        problem("docs/operations.md has no Deployment section")
    pages = ["README.md"] + sorted(
        os.path.join("docs", p) for p in os.listdir(os.path.join(src, "docs")) if p.endswith(".md"))
    for page in pages:
        with open(os.path.join(src, page), encoding="utf-8") as f:
            text = f.read()
        named = set(re.findall(r"`((?:deploy|tests|idl)/[A-Za-z0-9_./-]+)`", text))
        for name in sorted(named):
            if not os.path.exists(os.path.join(src, name)):
                problem(f"{page} names {name}, which does not exist")
        print(f"{page}: {len(named)} paths named, checked")


def check_configs(check_config, configs):
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for i, (label, text) in enumerate(sorted(configs.items())):
            path = os.path.join(tmp, f"{i}.yaml")
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
            paths.append((label, path))
        for label, path in paths:
            result = subprocess.run([check_config, path], capture_output=True, text=True)
            line = result.stdout.strip().replace(path, label)
            print(f"config {line}")
            if result.returncode != 0:
                problem(f"config {label}: dh3-service would not start: {line}")


if __name__ == "__main__":
    sys.exit(main())
