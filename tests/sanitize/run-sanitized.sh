#!/usr/bin/env bash
# Builds the project with sanitizers in a build directory of its own and runs
# the tests there. Part of tests/run-all.sh (the README's test command).
#
#   tests/sanitize/run-sanitized.sh address   AddressSanitizer + UndefinedBehaviorSanitizer,
#                                             every C++ test (see `selection` below)
#   tests/sanitize/run-sanitized.sh thread    ThreadSanitizer, the hand, bus, service and reliability tests
#
# SANITIZE_BUILD_DIR (default build-asan / build-tsan) and JOBS (default 2) may be set;
# extra arguments go to ctest. Fast DDS itself comes from Debian uninstrumented:
# the sanitizers see the project's code (and the generated IDL code), and the
# suppression files here name only findings inside Fast DDS, each with why.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
source "$here/address-selection.sh"
cd "$here/../.."
mode=${1:?"address or thread"}
shift
jobs=${JOBS:-2}

# Every process the tests start (dh3-service, dh3-sim, dh3ctl, ...) writes its
# ASan, LSan and TSan findings here, so one found in a child process fails the
# run even when the test that started it passed. UBSan (beside ASan) writes to
# stderr whatever log_path says; it stops the process at the first finding, so
# a test sees it as a crash of the program it runs.
reports=$PWD/build-$mode-reports
rm -rf "$reports" && mkdir -p "$reports"

case $mode in
  address)
    build=${SANITIZE_BUILD_DIR:-build-asan}
    sanitize=address,undefined
    # What ASan and UBSan can find bugs in: the project's C++, every test
    # program of the labels below and the programs those tests start. Only
    # these targets are built (no benchmarks, fuzzers or Python module): the
    # test programs come from test-programs.txt (written by tests/CMakeLists.txt),
    # so a new one is built and run here without being named.
    targets=(dh3-service dh3-sim dh3ctl dh3-web dh3-ros2 pick_loop event_watcher)
    programs_of_labels=$address_labels
    # Which tests: tests/sanitize/address-selection.sh (tests/run-all.sh runs
    # the rest in the plain build).
    selection=(-L "$address_labels" -E "$address_left_out")
    # new_delete_type_mismatch=0: Debian's libfastrtps 2.9 frees objects of its
    # own with a smaller size than it allocated them with (~RTPSReader and
    # ~RTPSWriter, seen on every reader and writer deleted). Allocation and
    # release are both inside the library, and ASan cannot suppress this check
    # by stack, only switch it off; every other ASan check stays on.
    export ASAN_OPTIONS=detect_leaks=1:new_delete_type_mismatch=0:log_path=$reports/asan
    export LSAN_OPTIONS=suppressions=$here/lsan.supp:print_suppressions=0
    export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
    ;;
  thread)
    build=${SANITIZE_BUILD_DIR:-build-tsan}
    sanitize=thread
    # The hand layer, the buses, the service's DDS side, metrics and app, and
    # the service as a process under faults (dh3-service, dh3-sim and dh3ctl are
    # built sanitized too). Only these test programs are built; ctest lists
    # each one not built as "<program>_NOT_BUILT", which the selection leaves out.
    # dh3-web's HTTP workers and push stream (test_web_service runs it as a
    # process) are threads over the client's callbacks.
    targets=(test_hand test_bus test_dds test_app test_metrics test_service test_reliability
             test_web_api test_web_service dh3-service dh3-sim dh3ctl dh3-web)
    # Not reliability.client_burst (see address), nor the docs' checks: they
    # read the text and the tests a full build lists, and run in the plain build.
    selection=(-L '^(unit|integration|reliability)$'
               -E '(_NOT_BUILT$|^install\.|^docs\.|^reliability\.client_burst$)')
    export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$here/tsan.supp:log_path=$reports/tsan"
    ;;
  *)
    echo "usage: $0 address|thread [ctest args]" >&2
    exit 2
    ;;
esac

echo "== $sanitize: configure and build in $build"
# -O1 -g1: fast enough to run, line tables for the reports' stacks, and half
# the compile time of -O2 -g, which under ASan + UBSan made this the longest
# phase of the test command. Warnings are the Release build's to fail on
# (tests/run-all.sh: -O3, every file): GCC's flow warnings differ by
# optimization level, and one seen only at -O1 says nothing of the users' build.
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DDH3_WERROR=OFF -DDH3_SANITIZE="$sanitize" \
  -DDH3_BUILD_PYTHON=OFF >/dev/null
if [[ -n ${programs_of_labels:-} ]]; then
  # "<program> <label>,<label>..." per line: the programs with a label selected.
  while read -r program labels; do
    for label in ${labels//,/ }; do
      if [[ $label =~ $programs_of_labels ]]; then targets+=("$program"); break; fi
    done
  done <"$build/test-programs.txt"
fi
cmake --build "$build" -j "$jobs" --target "${targets[@]}"
echo "== $sanitize: tests"
status=0
ctest --test-dir "$build" --output-on-failure -j "$jobs" "${selection[@]}" "$@" || status=$?

found=("$reports"/*)
if [[ -e ${found[0]} ]]; then
  echo "== $sanitize: ${#found[@]} report(s) in $reports"
  for report in "${found[@]}"; do
    echo "--- $report"
    head -n 60 "$report"
  done
  status=1
else
  echo "== $sanitize: no findings"
fi
exit "$status"
