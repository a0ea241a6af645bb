#!/usr/bin/env python3
"""Runs every shell example of README.md and docs/*.md against dh3-service on
the simulator, so that an example a reader copies works as written.

    run_examples.py SOURCE_DIR BUILD_DIR PROGRAM...

PROGRAM: the build's programs that examples may name bare, as installed
(dh3ctl, dh3-service, dh3-sim, ...).

A shell example is a fenced block marked sh, bash, shell or console (also
indented, in a list). Each one either runs here, or says why not in an HTML
comment on the line before it:

    <!-- example: covered by CTEST[, CTEST...][: why] -->
        what it does runs in those ctest tests (a name or a glob such as
        RecordReplayTest.*); it does not run here as written (systemd on a
        cell PC, containers, a kernel with CAN); the names must exist
    <!-- example: not run: REASON -->
        nothing here can run it; kept for the few that need what no test has
    <!-- example: alternatives -->
        the lines are alternatives (ways to start the service): each
        line runs alone

A block that runs is a bash script (errexit, pipefail) in a folder of its own
where build/ is the build tree and the source's folders (deploy/, client/,
...) are at hand; HOME is a scratch folder; the build's programs are first on
PATH for examples that name them bare (dh3ctl, as installed). Every command
must exit 0. A program that runs until stopped (dh3-service, dh3-web,
dh3-ros2, dh3-sim, `dh3ctl events`, `dh3ctl status --watch`, candump) is
started in the background, waited for until it prints its ready line (dh3-web
also until its health shows hands, as a reader sees them on the page), must
still run when the block ends, and must exit 0 on SIGINT (Ctrl-C) then.

Where an example shows output, as a comment `# prints: TEXT` (`prints:` may
follow other words of the comment; TEXT is the rest of it), the command's
output must have a line that contains TEXT, where `...` stands for any text
and the words N and PORT for a number; for a program that runs until
stopped, TEXT is its ready line.

Everything runs in a network namespace of the test's own (loopback only), so
the examples' DDS domain 0, service name dh3 and fixed ports (8080, 9000) are
its own and nothing leaves the machine. One dh3-service --bus sim:1,2,3 (the
README's) serves the blocks in order, so state carries from block to block as
in a reader's session; a block that starts a dh3-service of its own runs in a
namespace of its own. Exit 0 when every example ran or is marked, 1 otherwise;
77 (skip) when no network namespace can be made, after the markers were
checked.
"""
import fnmatch
import glob
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time

SHELL_LANGUAGES = {"sh", "bash", "shell", "console"}
MARKER = re.compile(r"^\s*<!--\s*example:\s*(.*?)\s*-->\s*$")
FENCE = re.compile(r"^(\s*)(```+|~~~+)\s*([\w+-]*)")
BLOCK_TIMEOUT_S = 40
READY_TIMEOUT_S = 20
# What a program that runs until stopped prints once it serves; the key is the
# program's name, and for dh3ctl the subcommand or option that keeps it running.
READY = {
    "dh3-service": r"service '[^']*' on DDS domain [0-9]+",
    "dh3-web": r"dh3-web: serving http://",
    "dh3-ros2": r"dh3-ros2: publishing joint states on ",
    "dh3-sim": r"^(listening |serving [0-9]+ hands? on )",
    "dh3ctl events": r"watching events",
    "dh3ctl --watch": r"^[^ ]+/[^ ]+/[0-9]+ ",
    "candump": r"",
}
# A line that makes a block without a language look like commands to run.
COMMAND_LIKE = re.compile(r"^\s*(\$ |build/|deploy/|tests/|sudo |dh3ctl |dh3-)")


class Block:
    def __init__(self, doc, line, language, text, marker):
        self.doc, self.line, self.language = doc, line, language
        self.text, self.marker = text, marker

    def where(self):
        return f"{self.doc}:{self.line}"


def extract(source):
    """Every fenced block of README.md and docs/*.md, with the marker before it."""
    docs = ["README.md"] + sorted(os.path.relpath(p, source)
                                  for p in glob.glob(os.path.join(source, "docs", "*.md")))
    blocks, problems = [], []
    for doc in docs:
        with open(os.path.join(source, doc), encoding="utf-8") as f:
            lines = f.read().split("\n")
        i = 0
        while i < len(lines):
            match = FENCE.match(lines[i])
            if not match:
                i += 1
                continue
            indent, fence, language = match.group(1), match.group(2), match.group(3).lower()
            start, body = i + 1, []
            i += 1
            while i < len(lines) and not lines[i].strip().startswith(fence):
                body.append(lines[i][len(indent):] if lines[i].startswith(indent) else lines[i])
                i += 1
            i += 1
            before = lines[start - 2] if start >= 2 else ""
            marker = MARKER.match(before)
            marker = marker.group(1) if marker else None
            if language in SHELL_LANGUAGES:
                blocks.append(Block(doc, start, language, "\n".join(body), marker))
            elif not language and any(COMMAND_LIKE.match(b) for b in body):
                problems.append(f"{doc}:{start}: a block without a language holds commands: "
                                "mark it ```sh so that it is run (or marked)")
    return blocks, problems


def ctest_names(build):
    listing = subprocess.run(["ctest", "--test-dir", build, "-N"], capture_output=True,
                             text=True, check=False).stdout
    return re.findall(r"^\s*Test\s+#\d+: (\S+)", listing, re.M)


def check_markers(blocks, build):
    """Problems with the markers: unknown kinds, reasons missing, tests not there."""
    problems, names = [], None
    for block in blocks:
        marker = block.marker
        if marker is None or marker == "alternatives":
            continue
        if marker.startswith("not run:"):
            if not marker[len("not run:"):].strip():
                problems.append(f"{block.where()}: 'not run' without a reason")
            continue
        if marker.startswith("covered by "):
            if names is None:
                names = ctest_names(build)
            wanted = marker[len("covered by "):].split(":")[0]
            for name in (n.strip() for n in wanted.split(",")):
                if not any(fnmatch.fnmatchcase(n, name) for n in names):
                    unbuilt = [n for n in names if n.endswith("_NOT_BUILT")]
                    hint = (f" (ctest lists {len(unbuilt)} test programs not built, "
                            f"e.g. {unbuilt[0]}: build them all)" if unbuilt else "")
                    problems.append(f"{block.where()}: covered by '{name}', which is no "
                                    f"ctest test of {build}{hint}")
            continue
        problems.append(f"{block.where()}: unknown marker '{marker}' (covered by TEST, "
                        "not run: REASON, alternatives)")
    return problems


def logical_lines(text):
    """The block's commands: continuation lines joined, blank lines and comments left out."""
    lines, current = [], ""
    for raw in text.split("\n"):
        if raw.endswith("\\"):
            current += raw + "\n"
            continue
        current += raw
        if current.strip() and not current.strip().startswith("#"):
            lines.append(current)
        current = ""
    return lines


def split_comment(line):
    """(command, comment) of a line: a '#' outside quotes after a blank starts a comment."""
    quote, previous = None, " "
    for i, c in enumerate(line):
        if quote:
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c == "#" and previous.isspace():
            return line[:i].rstrip(), line[i + 1:].strip()
        previous = c
    return line.rstrip(), ""


def commands_of(command):
    """The words of each simple command in a line, and what joins them."""
    lexer = shlex.shlex(command, posix=True, punctuation_chars=True)
    lexer.whitespace_split = True
    parts, words = [], []
    for token in lexer:
        if token in ("&&", "||", "|", ";", "&"):
            parts.append((words, token))
            words = []
        else:
            words.append(token)
    parts.append((words, ""))
    return [(w, j) for w, j in parts if w]


def program_of(words):
    """The program a simple command runs: its first word after any VAR=value."""
    for word in words:
        if not re.match(r"^\w+=", word):
            return os.path.basename(word)
    return ""


def runs_until_stopped(words):
    """The READY key of a command that runs until it is stopped, or None."""
    program = program_of(words)
    if program == "dh3ctl":
        if "--help" in words:
            return None
        if "events" in words:
            return "dh3ctl events"
        if "--watch" in words:
            return "dh3ctl --watch"
        return None
    if program in READY and not {"--help", "--version"} & set(words):
        return program
    return None


def pattern_of(text):
    """An extended regular expression for a `# prints:` text."""
    pieces = re.split(r"(\.\.\.|\bN\b|\bPORT\b)", text)
    out = []
    for piece in pieces:
        if piece == "...":
            out.append(".*")
        elif piece in ("N", "PORT"):
            out.append("-?[0-9]+")
        else:
            out.append(re.sub(r"([\\.^$*+?()\[\]{}|])", r"\\\1", piece))
    return "".join(out)


PRELUDE = r"""
set -eo pipefail
__daemons=()
__logs=()
__fail() { echo "EXAMPLE FAILED: $*" >&2; exit 1; }
trap 'echo "EXAMPLE FAILED (exit status $?): $BASH_COMMAND" >&2' ERR
__cleanup() {
  for pid in "${__daemons[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
}
trap __cleanup EXIT
# __daemon READY_ERE COMMAND...: starts COMMAND in the background and waits
# until its output has a line matching READY_ERE (or it is gone).
__daemon() {
  local ready=$1 log
  shift
  log=$(mktemp -p "$EXAMPLE_LOGS" daemon.XXXX)
  "$@" >"$log" 2>&1 &
  local pid=$!
  __daemons+=("$pid")
  __logs+=("$log")
  local deadline=$((SECONDS + READY_TIMEOUT))
  until grep -Eq -- "$ready" "$log"; do
    if ! kill -0 "$pid" 2>/dev/null; then
      cat "$log" >&2
      wait "$pid" && status=0 || status=$?
      __fail "'$*' ended (exit status $status) before printing /$ready/"
    fi
    ((SECONDS < deadline)) || { cat "$log" >&2; __fail "'$*' printed no /$ready/ in $READY_TIMEOUT s"; }
    sleep 0.05
  done
  echo "started: $* (pid $pid): $(grep -Em1 -- "$ready" "$log" || true)"
  [[ $(basename "$1") != dh3-web ]] || __web_sees_hands "$log"
}
# dh3-web answers UNKNOWN_HAND for a hand it has not seen yet, as it does
# right after start: a reader sees the hands on the page before the next
# command, and so does this, on dh3-web's health.
__web_sees_hands() {
  local url deadline=$((SECONDS + READY_TIMEOUT))
  url=$(grep -Eom1 'http://[^ ]+/' "$1")
  until curl -s "${url}api/health" | grep -Eq '"hands":[1-9]'; do
    ((SECONDS < deadline)) || __fail "dh3-web at $url saw no hand in $READY_TIMEOUT s"
    sleep 0.05
  done
}
# __expect ERE TEXT OUTPUT: the output has a line matching ERE.
__expect() {
  grep -Eq -- "$1" <<<"$3" || __fail "no line of the output matches 'prints: $2'"
}
# Stops what __daemon started, newest first: each must still run, and exit 0 on SIGINT.
__stop_daemons() {
  local i pid status
  for ((i = ${#__daemons[@]} - 1; i >= 0; i--)); do
    pid=${__daemons[i]}
    if ! kill -0 "$pid" 2>/dev/null; then
      cat "${__logs[i]}" >&2
      wait "$pid" && status=0 || status=$?
      __fail "pid $pid ended (exit status $status) before the block did"
    fi
    kill -INT "$pid"
    wait "$pid" && status=0 || status=$?
    echo "stopped pid $pid: exit status $status"
    if ((status != 0)); then cat "${__logs[i]}" >&2; __fail "pid $pid exited $status on SIGINT"; fi
  done
  __daemons=()
}
"""


def script_of(lines):
    """The bash script that runs these logical lines as the checks say."""
    out = [PRELUDE]
    for line in lines:
        command, comment = split_comment(line)
        prints = comment.split("prints:", 1)[1].strip() if "prints:" in comment else ""
        parts = commands_of(command)
        waits = [runs_until_stopped(words) for words, _ in parts]
        out.append(f"echo {shlex.quote('$ ' + line)}")
        if any(waits):
            if len(parts) != 1:
                raise ValueError(f"a program that runs until stopped in a compound line: {line}")
            ready = pattern_of(prints) if prints else READY[waits[0]]
            plain = command.rstrip().rstrip("&").rstrip()
            out.append(f"__daemon {shlex.quote(ready)} {plain}")
        elif prints:
            out.append(f"__out=$( {{ {command}\n}} 2>&1 ) || {{ __s=$?; printf '%s\\n' "
                       f"\"$__out\"; __fail \"exit status $__s\"; }}")
            out.append("printf '%s\\n' \"$__out\"")
            out.append(f"__expect {shlex.quote(pattern_of(prints))} {shlex.quote(prints)} "
                       "\"$__out\"")
        else:
            out.append(line)
    out.append("__stop_daemons")
    return "\n".join(out) + "\n"


def starts_a_service(lines):
    return any(program_of(words) == "dh3-service"
               for line in lines for words, _ in commands_of(split_comment(line)[0]))


def enter_namespace():
    """Runs this script again in a network namespace of its own; returns its exit code,
    or None when none can be made."""
    unshare = shutil.which("unshare")
    if not unshare or not shutil.which("ip"):
        return None
    flags = ["--net"] if os.geteuid() == 0 else ["--user", "--map-root-user", "--net"]
    probe = subprocess.run([unshare, *flags, "true"], capture_output=True, check=False)
    if probe.returncode != 0:
        return None
    env = dict(os.environ, DH3_EXAMPLES_NAMESPACE="1")
    return subprocess.run([unshare, *flags, sys.executable, *sys.argv], env=env,
                          check=False).returncode


def make_workspace(source, build, programs, scratch):
    """A folder laid out as a clone with its build tree, a HOME and a PATH of the build's
    programs."""
    work = os.path.join(scratch, "work")
    home = os.path.join(scratch, "home")
    bin_dir = os.path.join(scratch, "bin")
    logs = os.path.join(scratch, "logs")
    for folder in (work, home, bin_dir, logs):
        os.makedirs(folder)
    for name in os.listdir(source):
        if name != "build" and not name.startswith("."):
            os.symlink(os.path.join(source, name), os.path.join(work, name))
    os.symlink(build, os.path.join(work, "build"))
    for program in programs:
        os.symlink(program, os.path.join(bin_dir, os.path.basename(program)))
    env = dict(os.environ, HOME=home, PATH=bin_dir + os.pathsep + os.environ["PATH"],
               EXAMPLE_LOGS=logs, READY_TIMEOUT=str(READY_TIMEOUT_S))
    env.pop("ROS_DISCOVERY_SERVER", None)
    env.pop("XDG_RUNTIME_DIR", None)
    return work, env


def run_script(script, work, env, own_namespace, label):
    path = os.path.join(env["EXAMPLE_LOGS"], f"{label}.sh")
    with open(path, "w", encoding="utf-8") as f:
        f.write(script)
    command = ["bash", path]
    if own_namespace:
        command = ["unshare", "--net", "bash", "-c", 'ip link set lo up && exec bash "$0"', path]
    started = time.monotonic()
    process = subprocess.Popen(command, cwd=work, env=env, stdin=subprocess.DEVNULL,
                               stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        output, _ = process.communicate(timeout=BLOCK_TIMEOUT_S)
        status = process.returncode
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        output, _ = process.communicate()
        output += f"\nEXAMPLE FAILED: still running after {BLOCK_TIMEOUT_S} s\n"
        status = -1
    return status, output, time.monotonic() - started


def start_shared_service(work, env):
    log = open(os.path.join(env["EXAMPLE_LOGS"], "service.log"), "w+", encoding="utf-8")
    service = subprocess.Popen(["build/service/app/dh3-service/dh3-service", "--bus", "sim:1,2,3"],
                               cwd=work, env=env, stdout=log, stderr=subprocess.STDOUT)
    deadline = time.monotonic() + READY_TIMEOUT_S
    while time.monotonic() < deadline and service.poll() is None:
        log.seek(0)
        if re.search(READY["dh3-service"], log.read()):
            return service, log
        time.sleep(0.05)
    log.seek(0)
    sys.exit(f"FAILED: the examples' dh3-service did not start:\n{log.read()}")


def run_blocks(blocks, work, env):
    failures, ran = [], 0
    for n, block in enumerate(blocks):
        if block.marker and block.marker != "alternatives":
            continue
        lines = logical_lines(block.text)
        groups = [[line] for line in lines] if block.marker == "alternatives" else [lines]
        for k, group in enumerate(groups):
            try:
                script = script_of(group)
            except ValueError as error:
                failures.append(f"{block.where()}: {error}")
                continue
            own = starts_a_service(group)
            status, output, took = run_script(script, work, env, own, f"block{n}.{k}")
            ran += 1
            where = block.where() + (f" line {k + 1}" if len(groups) > 1 else "")
            print(f"== {where}: exit status {status}, {took:.1f} s"
                  f"{' (a network of its own)' if own else ''}")
            print("   " + output.rstrip().replace("\n", "\n   "))
            if status != 0:
                failures.append(f"{where}: exit status {status}")
    return failures, ran


def main():
    source, build = (os.path.abspath(a) for a in sys.argv[1:3])
    programs = [os.path.abspath(a) for a in sys.argv[3:]]
    blocks, problems = extract(source)
    inside = os.environ.get("DH3_EXAMPLES_NAMESPACE") == "1"
    if not inside:
        problems += check_markers(blocks, build)
        for block in blocks:
            print(f"{block.where()}: {block.marker or 'runs'}")
        if problems:
            print("\n".join(f"FAILED: {p}" for p in problems))
            return 1
        status = enter_namespace()
        if status is None:
            print("SKIP: no network namespace can be made here (unshare, ip): the examples "
                  "were not run; their markers were checked")
            return 77
        return status

    subprocess.run(["ip", "link", "set", "lo", "up"], check=True)
    with tempfile.TemporaryDirectory(prefix="dh3-examples-") as scratch:
        work, env = make_workspace(source, build, programs, scratch)
        service, log = start_shared_service(work, env)
        try:
            failures, ran = run_blocks(blocks, work, env)
        finally:
            service.send_signal(signal.SIGTERM)
            service_status = service.wait()
        if service_status != 0:
            log.seek(0)
            failures.append(f"the examples' dh3-service exited {service_status}:\n{log.read()}")
    covered = sum(1 for b in blocks if (b.marker or "").startswith("covered by "))
    not_run = sum(1 for b in blocks if (b.marker or "").startswith("not run:"))
    print(f"{len(blocks)} shell blocks: {len(blocks) - covered - not_run} ran ({ran} runs), "
          f"{covered} covered by other tests, {not_run} not run")
    if failures:
        print("\n".join(f"FAILED: {f}" for f in failures))
        return 1
    print("every example ran")
    return 0


if __name__ == "__main__":
    sys.exit(main())
