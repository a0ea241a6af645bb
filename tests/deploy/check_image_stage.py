#!/usr/bin/env python3
"""Checks what build-in-image.sh staged for the runtime image, on this host.

    check_image_stage.py SOURCE_DIR STAGE_DIR

The runtime stage installs only deploy/install-deps.sh --runtime's packages
and copies STAGE_DIR over its root. So:
- every shared library the staged programs and libraries need resolves, to a
  staged library or to a file of one of those packages or what they depend on
  (Depends/Pre-Depends, as apt installs them);
- the programs start: --version or --help exits 0;
- the default configuration, the health check and the XML profiles are there.

Prints one line per problem and exits 1 if there is any.
"""
import os
import re
import subprocess
import sys

problems = []


def problem(text):
    problems.append(text)
    print("PROBLEM: " + text)


def runtime_packages(src):
    with open(os.path.join(src, "deploy/install-deps.sh"), encoding="utf-8") as f:
        block = re.search(r"runtime_pkgs=\((.*?)\)", f.read(), re.S)
    return block.group(1).split() if block else []


def installed_packages():
    """name -> (set of dependency alternatives groups, provides)"""
    out = subprocess.run(
        ["dpkg-query", "-W", "-f", "${Package}\t${Depends}\t${Pre-Depends}\t${Provides}\t${db:Status-Abbrev}\n"],
        capture_output=True, text=True, check=True).stdout
    packages, provides = {}, {}
    for line in out.splitlines():
        name, depends, predepends, provided, status = line.split("\t")
        if not status.startswith("ii"):
            continue
        groups = []
        for item in filter(None, [d.strip() for d in (depends + "," + predepends).split(",")]):
            groups.append([re.sub(r"[\s(:].*", "", alt.strip()) for alt in item.split("|")])
        packages[name] = groups
        for p in filter(None, [p.strip() for p in provided.split(",")]):
            provides.setdefault(re.sub(r"[\s(].*", "", p), []).append(name)
    return packages, provides


def closure(roots, packages, provides):
    seen, todo = set(), list(roots)
    while todo:
        name = todo.pop()
        candidates = [name] if name in packages else provides.get(name, [])
        for c in candidates:
            if c in seen:
                continue
            seen.add(c)
            for group in packages[c]:
                todo.extend(alt for alt in group if alt in packages or alt in provides)
    return seen


def owner(path):
    tried = {path, os.path.realpath(path)}
    for p in list(tried):
        if p.startswith("/usr/lib/"):
            tried.add(p[len("/usr"):])
        elif p.startswith("/lib/"):
            tried.add("/usr" + p)
    for p in tried:
        result = subprocess.run(["dpkg", "-S", p], capture_output=True, text=True)
        if result.returncode == 0:
            return result.stdout.split(":")[0].split(",")[0].strip()
    return None


def is_elf(path):
    with open(path, "rb") as f:
        return f.read(4) == b"\x7fELF"


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    src, stage = sys.argv[1:]
    prefix = os.path.join(stage, "usr/local")
    libdir = os.path.join(prefix, "lib")
    env = dict(os.environ, LD_LIBRARY_PATH=libdir)

    packages, provides = installed_packages()
    runtime = runtime_packages(src)
    for name in runtime:
        if name not in packages:
            problem(f"runtime package {name} is not installed here (install-deps.sh --runtime)")
    allowed = closure(runtime, packages, provides)
    print(f"runtime packages {runtime}: {len(allowed)} with their dependencies")

    elves = []
    for d in (os.path.join(prefix, "bin"), libdir):
        for name in sorted(os.listdir(d)) if os.path.isdir(d) else []:
            path = os.path.join(d, name)
            if os.path.isfile(path) and not os.path.islink(path) and is_elf(path):
                elves.append(path)
    if not elves:
        problem("nothing staged")
    for path in elves:
        out = subprocess.run(["ldd", path], capture_output=True, text=True, env=env).stdout
        for line in out.splitlines():
            m = re.match(r"\s*(\S+) => (\S+)", line)
            if not m:
                continue
            lib, resolved = m.groups()
            if resolved == "not":
                problem(f"{path}: {lib} not found")
            elif resolved.startswith(stage):
                continue
            else:
                package = owner(resolved)
                if package not in allowed:
                    problem(f"{path}: {lib} comes from {package}, which the runtime stage lacks")
        print(f"linked: {os.path.relpath(path, stage)}")

    for program, flag in (("dh3-service", "--version"), ("dh3ctl", "--version"),
                          ("dh3-sim", "--help"), ("pick_loop", "--help"),
                          ("event_watcher", "--help")):
        path = os.path.join(prefix, "bin", program)
        if not os.access(path, os.X_OK):
            problem(f"{program} is not staged")
            continue
        result = subprocess.run([path, flag], capture_output=True, text=True, env=env)
        if result.returncode != 0:
            problem(f"{program} {flag} exited {result.returncode}: {result.stderr.strip()}")
        else:
            print(f"runs: {program} {flag}: {result.stdout.strip().splitlines()[0]}")

    for needed in ("etc/dh3/dh3.yaml", "usr/local/bin/dh3-healthcheck",
                   "usr/local/share/dh3/dds/udp_only.xml",
                   "usr/local/share/dh3/dds/discovery_client.xml",
                   "usr/local/share/dh3/dds/secure.xml"):
        if not os.path.exists(os.path.join(stage, needed)):
            problem(f"{needed} is not staged")

    if problems:
        print(f"{len(problems)} problem(s)")
        return 1
    print("image stage: no problems")
    return 0


if __name__ == "__main__":
    sys.exit(main())
