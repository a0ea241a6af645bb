#!/usr/bin/env bash
# The Debian packages installed, run, upgraded and purged for real, as on a
# cell PC: a Debian 12 container with systemd as init (podman run
# --systemd=always) on podman's default bridge network, whose apt reaches the
# machine's Debian archive. Checked, each as a user would see it:
#   - `apt-get install ./*.deb` pulls the dependencies from the archive and
#     starts dh3.service on the simulator: active, running as user dh3;
#   - the unit's hardening applies (no capabilities, no new privileges, a
#     seccomp filter, a read-only /usr and /etc) and `systemd-analyze security
#     dh3` prints its score; the unit allows AF_CAN;
#   - `dh3ctl list` shows the hands; `python3 -c 'import dh3'` (and the module
#     drives a hand); a C++ program built with find_package(dh3client) against
#     the installed libdh3client-dev drives a hand; the metrics answer;
#     `journalctl -u dh3` has the service's log;
#   - `systemctl stop dh3`: the service exits cleanly and a `dh3ctl events`
#     watcher sees every hand go offline;
#   - an edited /etc/dh3/dh3.yaml (another service name, DDS on every
#     interface, UDP only) takes effect on restart, and the service reaches
#     the network: dh3ctl on this machine, outside the container, finds it
#     over the bridge;
#   - upgrading to the same packages with a higher version keeps the edited
#     configuration and restarts the service with it;
#   - dh3-web.service is active with the token the package made, lists the
#     hands, refuses a command without the token and serves one with it;
#   - `apt-get purge` leaves no file, user, group or process of dh3 behind.
#
#   test_install.sh SOURCE_DIR DEBS_DIR UPGRADE_DEBS_DIR HOST_DH3CTL WORK_DIR
#
# WORK_DIR keeps apt's lists and downloaded packages between runs (the
# archive is still asked each time). The systemd image is tagged by a hash of
# tests/package/systemd.Containerfile and of the base image, and kept, so a
# rerun starts at once; the container is removed on every exit.
# Exit 77 (skipped) with the reason where no container engine can run.
set -uo pipefail
src=$1 host_ctl=$4
# podman -v takes absolute paths only.
debs=$(realpath "$2") upgrade_debs=$(realpath "$3") cache=$(realpath -m "$5")
here=$(cd "$(dirname "$0")" && pwd -P)
export CONTAINERS_CONF=${CONTAINERS_CONF:-$src/deploy/container/containers.conf}
name=dh3pkg$$
work=$(mktemp -d)
failures=0
fail() { echo "FAILED: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; }
skip() { echo "SKIP: $*"; exit 77; }
step() { echo "== $* ($((SECONDS - started)) s)"; }
cleanup() {
  podman rm --ignore -f -t 0 "$name" >/dev/null 2>&1
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
started=$SECONDS

[[ $(id -u) -eq 0 ]] || skip "needs root (rootful podman; CI runs as root)"
for deb in dh3-service dh3-tools libdh3client0.1 libdh3client-dev python3-dh3; do
  for dir in "$debs" "$upgrade_debs"; do
    compgen -G "$dir/${deb}_*.deb" >/dev/null || { fail "no $deb package in $dir"; exit 1; }
  done
done
version=$(dpkg-deb -f "$(compgen -G "$debs/dh3-service_*.deb")" Version)
upgrade_version=$(dpkg-deb -f "$(compgen -G "$upgrade_debs/dh3-service_*.deb")" Version)

# The engine, and the base image the container tests use (made from this
# machine's archive by build-image.sh, which also installs podman).
step "base image"
"$src/deploy/container/build-image.sh" --base-only >"$work/base.log" 2>&1 || {
  podman info >"$work/info" 2>&1 || skip "podman cannot run here: $(tail -n 1 "$work/info")"
  tail -n 20 "$work/base.log"
  fail "build-image.sh --base-only failed"
  exit 1
}
grep '^build-image:' "$work/base.log"
podman info >"$work/info" 2>&1 || skip "podman cannot run here: $(tail -n 1 "$work/info")"

step "systemd image"
base_id=$(podman image inspect --format '{{.Id}}' debian:bookworm)
hash=$( (cat "$here/systemd.Containerfile"; echo "$base_id") | sha256sum | cut -c1-16)
image=localhost/dh3-package-systemd:$hash
if podman image exists "$image"; then
  ok "systemd image $image is cached"
else
  # Images of an earlier Containerfile or base are of no use any more.
  podman images --format '{{.Repository}}:{{.Tag}}' | grep '^localhost/dh3-package-systemd:' |
    xargs -r podman rmi -f >/dev/null 2>&1
  if podman build --network=host -f "$here/systemd.Containerfile" -t "$image" "$here" >"$work/image.log" 2>&1; then
    ok "built systemd image $image"
  else
    tail -n 20 "$work/image.log"
    fail "podman build of the systemd image failed"
    exit 1
  fi
fi

# CAP_SYS_ADMIN: systemd sets up a service's sandbox (ProtectSystem=,
# ProtectHome=, PrivateTmp=) with mount namespaces, which podman's default
# capabilities do not allow; without it systemd skips them and the hardening
# would not be what a cell PC's systemd applies.
step "container"
mkdir -p "$cache/lists" "$cache/archives"
if ! podman run -d --name "$name" --systemd=always --cap-add SYS_ADMIN \
  -v "$debs:/debs:ro" -v "$upgrade_debs:/debs-upgrade:ro" -v "$here/consumer:/consumer:ro" \
  -v "$cache/lists:/var/lib/apt/lists" -v "$cache/archives:/var/cache/apt/archives" \
  "$image" >"$work/run.log" 2>&1; then
  cat "$work/run.log"
  fail "podman run --systemd=always failed"
  exit 1
fi
ctr() { podman exec "$name" "$@"; }
booted() { [[ $(ctr systemctl is-system-running 2>/dev/null) =~ ^(running|degraded)$ ]]; }
wait_for() {  # wait_for SECONDS COMMAND...: until COMMAND succeeds, twice a second
  local deadline=$((SECONDS + $1))
  shift
  until "$@"; do
    ((SECONDS < deadline)) || return 1
    sleep 0.5
  done
}
if wait_for 60 booted; then
  ok "systemd is PID 1 in the container: $(ctr systemctl is-system-running) ($(ctr readlink /proc/1/exe))"
else
  fail "systemd did not boot: $(ctr systemctl is-system-running 2>&1)"
  exit 1
fi
ctr sh -c 'find / -xdev -iname "*dh3*" -not -path "/proc/*" 2>/dev/null' >"$work/before"

step "apt-get install ./*.deb"
if ctr sh -c 'apt-get update -qq && cd /debs &&
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends ./*.deb' \
  </dev/null >"$work/install.log" 2>&1; then
  ok "apt-get install ./*.deb: $(grep -E '^Need to get|^[0-9]+ upgraded' "$work/install.log" | tr '\n' ' ')"
else
  tail -n 30 "$work/install.log"
  fail "apt-get install ./*.deb failed"
  exit 1
fi
pulled=$(grep -c '^Setting up lib\(fastrtps\|fastcdr\|spdlog\|yaml-cpp\|prometheus-cpp\)' "$work/install.log")
((pulled >= 5)) && ok "apt pulled dh3's dependencies from the archive: $(grep -o '^Setting up lib\(fastrtps\|fastcdr\|spdlog\|yaml-cpp\|prometheus-cpp\)[^ ]*' "$work/install.log" | sed 's/Setting up //' | tr '\n' ' ')" ||
  fail "apt-get did not install Fast DDS, spdlog, yaml-cpp and prometheus-cpp from the archive"
[[ $(ctr dpkg-query -W -f '${Version}' dh3-service) == "$version" ]] && ok "dh3-service $version installed" ||
  fail "dh3-service is not at $version"

step "dh3.service"
active() { [[ $(ctr systemctl is-active dh3) == active ]]; }
if wait_for 30 active; then
  ok "systemctl is-active dh3: active (started by the package)"
else
  fail "dh3.service is not active: $(ctr systemctl status --no-pager dh3 2>&1 | tail -n 15)"
fi
[[ $(ctr systemctl is-enabled dh3) == enabled ]] && ok "dh3.service is enabled" || fail "dh3.service is not enabled"
pid=$(ctr systemctl show -p MainPID --value dh3)
if [[ $pid =~ ^[1-9][0-9]*$ ]]; then
  user=$(ctr ps -o user= -p "$pid")
  [[ $user == dh3 ]] && ok "dh3-service (pid $pid) runs as user dh3" || fail "dh3-service runs as '$user'"
  ctr grep -E '^(CapEff|CapBnd|NoNewPrivs|Seccomp):' "/proc/$pid/status" >"$work/status"
  if grep -q '^CapEff:[[:space:]]*0\+$' "$work/status" && grep -q '^CapBnd:[[:space:]]*0\+$' "$work/status" &&
    grep -q '^NoNewPrivs:[[:space:]]*1$' "$work/status" && grep -q '^Seccomp:[[:space:]]*2$' "$work/status"; then
    ok "hardening applies: no capabilities, no new privileges, a seccomp filter ($(tr -s '\t\n' '  ' <"$work/status"))"
  else
    fail "the unit's hardening is not in force: $(tr -s '\t\n' '  ' <"$work/status")"
  fi
  # ProtectSystem=strict: what the service sees of / is read-only.
  ro=$(ctr awk '$5 == "/usr" || $5 == "/etc" || $5 == "/" { split($6, o, ","); print $5 "=" o[1] }' "/proc/$pid/mountinfo" | sort -u | tr '\n' ' ')
  [[ $ro == *ro* && $ro != *=rw* ]] && ok "ProtectSystem=strict: the service's view of the file system: $ro" ||
    fail "the service's file system is not read-only: $ro"
else
  fail "no main process of dh3.service"
fi
ctr systemd-analyze security --no-pager dh3 >"$work/security" 2>&1
score=$(grep -o 'Overall exposure level for dh3.service:.*' "$work/security")
[[ -n $score ]] && echo "systemd-analyze security dh3: $score" || fail "systemd-analyze security dh3: $(tail -n 3 "$work/security")"
families=$(ctr systemctl show -p RestrictAddressFamilies --value dh3)
[[ " $families " == *" AF_CAN "* ]] && ok "the unit allows AF_CAN (RestrictAddressFamilies=$families)" ||
  fail "the unit does not allow AF_CAN: $families"

step "clients"
list() {  # list SERVICE [dh3ctl options]: dh3ctl list shows the 3 hands of SERVICE online
  local service=$1
  shift
  ctr dh3ctl --timeout 20 "$@" list >"$work/list" 2>&1 &&
    [[ $(grep -c "^$service/bus0/[123] .* yes " "$work/list") == 3 ]]
}
if wait_for 30 list cell; then
  ok "dh3ctl list: 3 hands online"
  sed 's/^/  /' "$work/list"
else
  fail "dh3ctl list:"; sed 's/^/  /' "$work/list"
fi
if ctr /usr/bin/python3 -c 'import dh3; print(dh3.__file__)' >"$work/py" 2>&1; then
  ok "python3 -c 'import dh3': $(cat "$work/py")"
else
  fail "import dh3: $(cat "$work/py")"
fi
if ctr /usr/bin/python3 -c '
import dh3
client = dh3.Client()
hand = client.wait_for_hand("cell/bus0/1", timeout=30.0)
reply = hand.initialize()
print("initialize:", reply.code.name)
raise SystemExit(0 if reply.ok else 1)' >"$work/py" 2>&1; then
  ok "the Python module initializes cell/bus0/1: $(tail -n 1 "$work/py")"
else
  fail "the Python module could not drive a hand: $(cat "$work/py")"
fi
if ctr sh -c 'cmake -S /consumer -B /root/consumer -DCMAKE_BUILD_TYPE=Release >/dev/null &&
    cmake --build /root/consumer >/dev/null && /root/consumer/drive_hand cell/bus0/3 30' >"$work/cpp" 2>&1 &&
  grep -q '^cell/bus0/3 at 30$' "$work/cpp"; then
  ok "a C++ program built with find_package(dh3client) against the installed files: $(tail -n 1 "$work/cpp")"
else
  fail "the C++ program against libdh3client-dev:"; sed 's/^/  /' "$work/cpp"
fi
ctr rm -rf /root/consumer
metrics() { ctr bash -c 'exec 3<>/dev/tcp/127.0.0.1/9464 && printf "GET /metrics HTTP/1.0\r\n\r\n" >&3 && timeout 10 cat <&3' >"$work/metrics" 2>&1; }
if metrics && [[ $(grep -c '^dh3_hand_online{.*} 1' "$work/metrics") == 3 ]]; then
  ok "metrics at http://127.0.0.1:9464/metrics: 3 hands online"
else
  fail "no metrics at 127.0.0.1:9464: $(head -n 3 "$work/metrics")"
fi
ctr journalctl -u dh3 --no-pager >"$work/journal" 2>&1
if grep -q "dh3-service\[[0-9]*\]: .*bus 'bus0': sim" "$work/journal"; then
  ok "journalctl -u dh3 has the service's log ($(grep -c 'dh3-service\[' "$work/journal") lines), e.g.: $(grep -m1 "bus 'bus0'" "$work/journal")"
else
  fail "journalctl -u dh3 lacks the service's start-up lines:"; tail -n 10 "$work/journal" | sed 's/^/  /'
fi

step "dh3-web.service"
[[ $(ctr systemctl is-active dh3-web) == active ]] && ok "systemctl is-active dh3-web: active (started by the package)" ||
  fail "dh3-web.service is not active: $(ctr systemctl status --no-pager dh3-web 2>&1 | tail -n 15)"
[[ $(ctr stat -c '%a %U %G' /etc/dh3/web.token 2>&1) == "640 root dh3-web" ]] &&
  ok "the package made /etc/dh3/web.token, 0640 root:dh3-web" ||
  fail "/etc/dh3/web.token: $(ctr stat -c '%a %U %G' /etc/dh3/web.token 2>&1)"
[[ $(ctr systemctl show -p User --value dh3-web) == dh3-web ]] && ok "dh3-web runs as user dh3-web" ||
  fail "dh3-web runs as $(ctr systemctl show -p User --value dh3-web)"
web() {  # web PATH [TOKEN]: POST (with a token) or GET, prints the status and the body
  ctr /usr/bin/python3 -c '
import sys, urllib.error, urllib.request
path, token = sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else None
request = urllib.request.Request("http://127.0.0.1:8080" + path, data=b"{}" if token is not None else None,
                                 headers={"Authorization": "Bearer " + token} if token else {})
try:
    with urllib.request.urlopen(request, timeout=20) as r:
        print(r.status, r.read().decode())
except urllib.error.HTTPError as e:
    print(e.code, e.read().decode())' "$@"
}
web_lists() { web /api/hands >"$work/web" 2>&1 && grep -q '"hand":"cell/bus0/3"' "$work/web"; }
wait_for 30 web_lists && ok "dh3-web lists the hands at 127.0.0.1:8080 in the container" ||
  { fail "dh3-web does not list the hands:"; sed 's/^/  /' "$work/web"; }
web /api/hands/cell/bus0/3/init "" >"$work/web" 2>&1
grep -q '^401 ' "$work/web" && ok "dh3-web refuses a command without the token: $(cut -c1-80 "$work/web")" ||
  { fail "dh3-web without the token:"; sed 's/^/  /' "$work/web"; }
web /api/hands/cell/bus0/3/init "$(ctr cat /etc/dh3/web.token)" >"$work/web" 2>&1
grep -q '^200 .*"ok":true' "$work/web" && ok "dh3-web initializes cell/bus0/3 with the package's token" ||
  { fail "dh3-web with the token:"; sed 's/^/  /' "$work/web"; }

step "systemctl stop dh3"
# The watcher is its own process in the container; its pid is kept to end it.
ctr sh -c 'echo $$ >/root/watch.pid; exec dh3ctl --timeout 30 events >/root/events.log 2>&1' &
watching() { ctr grep -q '^watching events' /root/events.log 2>/dev/null; }
wait_for 40 watching || fail "the event watcher did not start: $(ctr cat /root/events.log 2>&1)"
ctr systemctl stop dh3
result=$(ctr systemctl show -p Result --value dh3)
status=$(ctr systemctl show -p ExecMainStatus --value dh3)
[[ $result == success && $status == 0 ]] && ok "systemctl stop dh3: the service exited with status 0 (Result=$result)" ||
  fail "systemctl stop dh3: Result=$result, exit status $status"
offline() { [[ $(ctr grep -c 'OFFLINE.*service stopping' /root/events.log) == 3 ]]; }
if wait_for 30 offline; then
  ok "the watcher saw all 3 hands go OFFLINE (service stopping)"
else
  fail "the watcher did not see 3 hands go offline:"; ctr cat /root/events.log | sed 's/^/  /'
fi
ctr sh -c 'kill "$(cat /root/watch.pid)" 2>/dev/null; rm -f /root/watch.pid /root/events.log'
wait
ctr journalctl -u dh3 --no-pager | grep -q 'SIGTERM received, stopping' && ok "the journal has the service's stop" ||
  fail "the journal lacks 'SIGTERM received, stopping'"

step "an edited /etc/dh3/dh3.yaml takes effect on restart"
# Another name, a DDS domain of this run's own (the bridge is shared with
# other tests' containers), and DDS on every interface of the container.
domain=$((201 + $$ % 30))
# And the flight recorder on bus0, into the unit's StateDirectory.
ctr sed -i -e 's/^name: cell /name: cellb /' -e "s/^domain: 0 /domain: $domain /" \
  -e 's/^  interfaces: \[\]/  interfaces: ["*"]/' \
  -e 's|^    spec: sim$|    spec: sim\n    record: {dir: /var/lib/dh3/recordings}|' /etc/dh3/dh3.yaml
ctr grep -q '^name: cellb ' /etc/dh3/dh3.yaml && ctr grep -q "^domain: $domain " /etc/dh3/dh3.yaml &&
  ctr grep -q '^  interfaces: \["\*"\]' /etc/dh3/dh3.yaml ||
  fail "could not edit /etc/dh3/dh3.yaml: $(ctr sed -n '1,30p' /etc/dh3/dh3.yaml)"
ctr systemctl restart dh3
if wait_for 30 active && wait_for 30 list cellb --domain "$domain" --interface '*'; then
  ok "after the restart, dh3ctl lists the hands under the new name cellb, on domain $domain"
else
  fail "the edited configuration did not take effect:"; sed 's/^/  /' "$work/list"
fi
recorded() { ctr sh -c 'test -s /var/lib/dh3/recordings/bus0.000001.log'; }
if wait_for 10 recorded; then
  ok "bus0 records under the hardened unit: $(ctr stat -c '%n %s B %a %U' /var/lib/dh3/recordings/bus0.000001.log), $(ctr stat -c '%n %a %U' /var/lib/dh3)"
else
  fail "no recording of bus0 in /var/lib/dh3/recordings: $(ctr ls -la /var/lib/dh3 /var/lib/dh3/recordings 2>&1 | tr '\n' ' ')"
fi
# The service on the container's NIC, reached from outside it: this
# machine's dh3ctl on podman's bridge (the host's address on it).
address=$(podman inspect --format '{{.NetworkSettings.IPAddress}}' "$name")
gateway=$(podman inspect --format '{{.NetworkSettings.Gateway}}' "$name")
if [[ -n $gateway ]] && "$host_ctl" --udp-only --domain "$domain" --interface "$gateway" --timeout 30 list >"$work/hostlist" 2>&1 &&
  [[ $(grep -c '^cellb/bus0/[123] .* yes ' "$work/hostlist") == 3 ]]; then
  ok "the hardened service reaches the network: dh3ctl outside the container ($gateway) lists cellb's 3 hands at $address"
else
  fail "dh3ctl on the bridge ($gateway) did not reach the service at $address:"; sed 's/^/  /' "$work/hostlist"
fi

step "upgrade to $upgrade_version"
if ctr sh -c 'cd /debs-upgrade && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends ./*.deb' \
  </dev/null >"$work/upgrade.log" 2>&1; then
  ok "apt-get install of the $upgrade_version packages"
else
  tail -n 30 "$work/upgrade.log"
  fail "the upgrade failed"
fi
[[ $(ctr dpkg-query -W -f '${Version}' dh3-service) == "$upgrade_version" ]] &&
  ok "dh3-service is at $upgrade_version" || fail "dh3-service is not at $upgrade_version"
ctr grep -q '^name: cellb ' /etc/dh3/dh3.yaml && ok "the edited /etc/dh3/dh3.yaml was kept" ||
  fail "the upgrade replaced the edited configuration"
if wait_for 30 active && wait_for 30 list cellb --domain "$domain" --interface '*'; then
  ok "after the upgrade the service runs with the edited configuration (cellb)"
else
  fail "after the upgrade:"; sed 's/^/  /' "$work/list"
fi
new_pid=$(ctr systemctl show -p MainPID --value dh3)
[[ $new_pid != "$pid" ]] && ok "the upgrade restarted the service (pid $pid -> $new_pid)" ||
  fail "the service was not restarted by the upgrade"

step "apt-get purge"
if ctr sh -c 'DEBIAN_FRONTEND=noninteractive apt-get purge -y dh3-service dh3-tools dh3-web libdh3client0.1 \
    libdh3client-dev python3-dh3' </dev/null >"$work/purge.log" 2>&1; then
  ok "apt-get purge of the 6 packages"
else
  tail -n 20 "$work/purge.log"
  fail "apt-get purge failed"
fi
ctr getent passwd dh3 >/dev/null && fail "the user dh3 is still there" || ok "no user dh3"
ctr getent group dh3 >/dev/null && fail "the group dh3 is still there" || ok "no group dh3"
ctr ps -eo user=,pid=,args= >"$work/ps"
if grep -E 'dh3' "$work/ps"; then fail "processes of dh3 are left"; else ok "no process of dh3 is left"; fi
ctr sh -c 'find / -xdev -iname "*dh3*" -not -path "/proc/*" 2>/dev/null; find /tmp /run -iname "*dh3*" 2>/dev/null' |
  sort -u >"$work/after"
left=$(comm -13 <(sort -u "$work/before") "$work/after")
if [[ -z $left ]]; then
  ok "no file named after dh3 is left (/, /tmp, /run)"
else
  fail "files left after the purge:"; sed 's/^/  /' <<<"$left"
fi
ctr systemctl cat dh3 >/dev/null 2>&1 && fail "systemd still knows dh3.service" || ok "systemd no longer knows dh3.service"

echo "package install test took $((SECONDS - started)) s"
if ((failures)); then
  echo "$failures failure(s)"
  exit 1
fi
echo "package install: all checks passed"
