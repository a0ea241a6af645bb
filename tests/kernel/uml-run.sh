#!/usr/bin/env bash
# Runs one command as root inside a real Linux kernel with CAN: Debian's
# user-mode-linux (an ordinary process, no KVM), booted with this machine's
# root file system as its own through hostfs, so the build tree runs inside it
# as it is. The guest loads can, can-raw, can-dev, vcan and vxcan, brings up
# lo and a vcan0, runs the command in the current directory and halts.
#
#   tests/kernel/uml-run.sh [--timeout SECONDS] [--mem MB] -- COMMAND [ARGS...]
#
# Exit status: the command's own; 77 with a "SKIP: <reason>" line only where
# the kernel cannot boot here; 1 if it booted but the command never finished
# (hung past the timeout, or the guest crashed). The guest's output is printed
# as it was written; on trouble the kernel's console too.
set -uo pipefail

timeout_s=600
mem_mb=1536
while (($#)); do
  case $1 in
    --timeout) timeout_s=$2; shift 2 ;;
    --mem) mem_mb=$2; shift 2 ;;
    --) shift; break ;;
    *) echo "usage: $0 [--timeout S] [--mem MB] -- COMMAND [ARGS...]" >&2; exit 2 ;;
  esac
done
(($#)) || { echo "usage: $0 [--timeout S] [--mem MB] -- COMMAND [ARGS...]" >&2; exit 2; }

skip() { echo "SKIP: $*"; exit 77; }

kernel=$(command -v linux.uml || true)
[[ -n $kernel ]] || skip "no user-mode-linux kernel (linux.uml; deploy/install-deps.sh installs the package)"
modules_root=/usr/lib/uml/modules
version=$(ls "$modules_root" 2>/dev/null | head -n 1)
[[ -n $version ]] || skip "user-mode-linux has no modules under $modules_root"
# UML maps its memory from a file in TMPDIR, which must allow exec: /dev/shm does.
[[ -d /dev/shm && -w /dev/shm ]] || skip "no writable /dev/shm for the kernel's memory file"

# The run's files live under /tmp: the guest sees the host's /tmp through
# hostfs (its /dev is its own devtmpfs, so /dev/shm would not do).
run_dir=$(mktemp -d /tmp/dh3-uml.XXXXXX)
cleanup() { rm -rf "$run_dir"; }
trap cleanup EXIT

# A host whose XSAVE area is larger than the kernel's buffer for it (AVX-512,
# AMX) needs the shim uml_xstate_shim.c describes; it changes nothing elsewhere.
preload=
here=$(cd "$(dirname "$0")" && pwd)
if cc -O2 -shared -fPIC -o "$run_dir/xstate_shim.so" "$here/uml_xstate_shim.c" -ldl 2>"$run_dir/shim.err"; then
  preload=$run_dir/xstate_shim.so
fi

{
  echo '#!/bin/sh'
  echo 'export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin HOME=/root LANG=C.UTF-8'
  # The shim's guests keep off the XSAVE components it does not switch.
  echo 'export GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX512F,-AVX512VL,-AVX512BW,-AVX512DQ,-AVX512CD'
  # What the command's environment needs from the caller's: sanitizer and
  # test options, and the project's own variables.
  while IFS= read -r name; do
    printf 'export %s=%q\n' "$name" "${!name}"
  done < <(compgen -e | grep -E '^(DH3_|GTEST_|ASAN_|LSAN_|UBSAN_|TSAN_|SOAK_|CTEST_)' || true)
  cat <<GUEST
run=$run_dir
mount -t proc proc /proc
mount -t sysfs sys /sys
mkdir -p /dev/shm /dev/pts
mount -t tmpfs tmpfs /dev/shm
mount -t devpts devpts /dev/pts
mount -t tmpfs tmpfs /run
ip link set lo up
m=$modules_root/\$(uname -r)/kernel
for module in net/can/can.ko net/can/can-raw.ko net/can/can-bcm.ko net/can/can-gw.ko \\
    drivers/net/can/dev/can-dev.ko drivers/net/can/vcan.ko drivers/net/can/vxcan.ko; do
  [ -f "\$m/\$module" ] && insmod "\$m/\$module" 2>>"\$run/console-extra"
done
ip link add dev vcan0 type vcan && ip link set up dev vcan0
echo "\$(uname -r)" > "\$run/booted"
cd $(printf '%q' "$PWD")
$(printf '%q ' "$@") > "\$run/output" 2>&1 < /dev/null
echo \$? > "\$run/rc"
sync
halt -f
GUEST
} > "$run_dir/init"
chmod +x "$run_dir/init"

started=$(date +%s)
# UML starts helper processes of its own; run it in a process group of its
# own so a timeout takes them all.
TMPDIR=/dev/shm LD_PRELOAD=$preload setsid timeout --kill-after=10 "$timeout_s" "$kernel" \
  "mem=${mem_mb}M" rootfstype=hostfs rootflags=/ rw "init=$run_dir/init" \
  con=null con0=fd:0,fd:1 < /dev/null > "$run_dir/console" 2>&1
kernel_status=$?
elapsed=$(($(date +%s) - started))

[[ -f $run_dir/output ]] && cat "$run_dir/output"
if [[ -f $run_dir/rc ]]; then
  rc=$(cat "$run_dir/rc")
  echo "uml-run: linux $(cat "$run_dir/booted") ran '$*' in ${elapsed} s, exit status $rc"
  exit "$rc"
fi
echo "---- kernel console (last 40 lines) ----"
grep -v '^ \[<' "$run_dir/console" | tail -n 40
[[ -f $run_dir/console-extra ]] && cat "$run_dir/console-extra"
if [[ -f $run_dir/booted ]]; then
  echo "uml-run: FAIL: '$*' did not finish in the guest within ${timeout_s} s (kernel exit $kernel_status)"
  exit 1
fi
skip "the user-mode-linux kernel did not boot here (exit $kernel_status); its console is above"
