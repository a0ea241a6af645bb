#!/usr/bin/env bash
# The README's test command: install dependencies, configure, build, run every
# test (kernel CAN tests inside user-mode Linux and container tests included):
# the C++ tests under AddressSanitizer + UBSan, everything else in the Release
# build; then the hand, bus and service tests again under ThreadSanitizer
# (tests/sanitize/run-sanitized.sh, tests/sanitize/address-selection.sh).
# Prints how long each phase took.
#   tests/run-all.sh [extra ctest args]
# BUILD_DIR (default build) and JOBS (default 2) may be set; SANITIZERS=0 skips
# the sanitizer builds and runs every test in the Release build (for a quick
# local run; CI runs them).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
jobs=${JOBS:-2}

phases=()
phase_started=$SECONDS
# Ends the phase named $1: prints and remembers how long it took.
end_phase() {
  local took=$((SECONDS - phase_started))
  phases+=("$(printf '%-28s %4d min %02d s' "$1" $((took / 60)) $((took % 60)))")
  echo "== phase '$1' took $((took / 60)) min $((took % 60)) s"
  phase_started=$SECONDS
}
print_phases() {
  echo "== time per phase"
  printf '   %s\n' "${phases[@]}"
  echo "   total                        $((SECONDS / 60)) min $((SECONDS % 60)) s"
}

deploy/install-deps.sh
end_phase "install dependencies"
# Three build trees (plain, ASan, TSan) compile mostly the same files; ccache
# keeps what a previous run compiled. Paths are taken relative to the clone, so
# another clone on the same machine hits the same entries.
if [[ -z ${CMAKE_CXX_COMPILER_LAUNCHER:-} ]] && command -v ccache >/dev/null; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=true
fi
# Release (-O3), as users build and as the Debian packages are made from this
# tree (package.debs): a warning only the optimizer sees shows here first.
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DDH3_WERROR=ON
cmake --build "$build" -j "$jobs"
# The ROS 2 layout test's independent encoder (npm, test-only).
tests/ros2/install-npm.sh "$build/ros2-npm"
end_phase "build"
status=0
# What failed, gathered from each ctest run's console output for the end of the log.
source tests/support/failure-summary.sh
failures=$(mktemp)
console=$(mktemp)
trap 'rm -f "$failures" "$console"' EXIT
# Runs ctest on the Release build with the arguments given; ctest lists skipped
# tests without their reason, so this prints the reason each gave (GoogleTest's
# "Skipped" message, or a script's "SKIP:" line).
run_ctest() {
  ctest --test-dir "$build" --output-on-failure -j "$jobs" "$@" | tee "$console" || status=$?
  failed_tests_in "$console" "failed in $build" >>"$failures"
  local log="$build/Testing/Temporary/LastTest.log"
  if [[ -f $log ]] && grep -q -E ': Skipped$|^SKIP: ' "$log"; then
    echo "Skipped tests and their reasons:"
    awk '/: Skipped$/ { getline reason; print "  " reason } /^SKIP: / { print "  " $0 }' "$log" | sort -u
  fi
}
if [[ ${SANITIZERS:-1} != 0 ]]; then
  # The C++ tests run once, under AddressSanitizer + UBSan below; here every
  # other test: scripts, packages, containers, the kernel, Python, the browser,
  # and the C++ tests the sanitized run leaves out (address-selection.sh).
  source tests/sanitize/address-selection.sh
  run_ctest -LE "$address_labels" "$@"
  run_ctest -L "$address_labels" -R "$address_left_out" "$@"
else
  run_ctest "$@"
fi
end_phase "tests"

# The names of the tests ctest would run in build directory $1 with the
# selection given after it, sorted.
test_names() {
  # A parameterized test's name ends in "  # GetParam() = ...", which can hold an
  # address: the name alone is compared.
  ctest --test-dir "$1" -N "${@:2}" | sed -n 's/^ *Test *#[0-9]*: //p' | sed 's/  # .*//' | sort -u
}
if [[ ${SANITIZERS:-1} != 0 ]]; then
  for mode in address thread; do
    JOBS=$jobs tests/sanitize/run-sanitized.sh "$mode" "$@" | tee "$console" || status=1
    failed_tests_in "$console" "failed under $mode sanitizer" >>"$failures"
    sanitizer_reports_in "build-$mode-reports" >>"$failures"
    end_phase "$mode sanitizer"
  done
  # Every test ran in one of the two builds: one the sanitized build did not
  # build would otherwise go unnoticed.
  unrun=$(comm -23 <(test_names "$build") \
    <(sort -u <(test_names "$build" -LE "$address_labels") \
      <(test_names "$build" -L "$address_labels" -R "$address_left_out") \
      <(test_names build-asan -L "$address_labels" -E "$address_left_out")))
  if [[ -n $unrun ]]; then
    echo "== tests neither build ran (add their program to the sanitized build):"
    sed 's/^/   /' <<<"$unrun"
    status=1
  fi
else
  echo "SANITIZERS=0: the sanitizer runs were skipped"
fi
if [[ -s $failures ]]; then
  echo "== what failed (the details are above)"
  cat "$failures"
fi
print_phases
exit "$status"
