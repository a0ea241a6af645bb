#!/usr/bin/env bash
# The README's test command: install dependencies, configure, build, run every
# test; then the whole suite again under AddressSanitizer + UBSan and the hand,
# bus and service tests under ThreadSanitizer (tests/sanitize/run-sanitized.sh).
#   tests/run-all.sh [extra ctest args]
# BUILD_DIR (default build) and JOBS (default 2) may be set; SANITIZERS=0 skips
# the sanitizer builds (for a quick local run; CI runs them).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
jobs=${JOBS:-2}

deploy/install-deps.sh
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build "$build" -j "$jobs"
status=0
ctest --test-dir "$build" --output-on-failure -j "$jobs" "$@" || status=$?

# ctest lists skipped tests without their reason; print the reason each gave
# (GoogleTest's "Skipped" message, or a netns script's "SKIP:" line).
log="$build/Testing/Temporary/LastTest.log"
if [[ -f $log ]] && grep -q -E ': Skipped$|^SKIP: ' "$log"; then
  echo "Skipped tests and their reasons:"
  awk '/: Skipped$/ { getline reason; print "  " reason } /^SKIP: / { print "  " $0 }' "$log" | sort -u
fi

if [[ ${SANITIZERS:-1} != 0 ]]; then
  for mode in address thread; do
    JOBS=$jobs tests/sanitize/run-sanitized.sh "$mode" "$@" || status=1
  done
else
  echo "SANITIZERS=0: the sanitizer runs were skipped"
fi
exit "$status"
