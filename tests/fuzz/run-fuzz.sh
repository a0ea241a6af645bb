#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UBSan) and runs
# each for a bounded time on a copy of its seed corpus (the spec's frames).
#   tests/fuzz/run-fuzz.sh WORK_DIR [SECONDS_PER_TARGET]
# Exit 77 (ctest: skipped) with the reason when clang or libFuzzer is missing.
# A crash leaves its input in WORK_DIR/<target>/; keep it as a regression case
# by copying it into tests/fuzz/corpus/<target>/ once the bug is fixed.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
work=${1:?work directory}
seconds=${2:-20}
mkdir -p "$work"

cxx=$(command -v clang++ || true)
if [[ -z $cxx ]]; then
  echo "SKIP: clang++ is not installed (deploy/install-deps.sh installs it)"
  exit 77
fi
probe="$work/probe.cpp"
printf 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }\n' >"$probe"
if ! "$cxx" -fsanitize=fuzzer "$probe" -o "$work/probe" 2>"$work/probe.log"; then
  echo "SKIP: clang++ cannot link libFuzzer: $(head -1 "$work/probe.log")"
  exit 77
fi

flags=(-std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all
       -I "$root/service")
protocol=("$root"/service/protocol/*.cpp)
status=0
for target in stream_decoder payload; do
  binary="$work/fuzz_$target"
  "$cxx" "${flags[@]}" "$here/fuzz_$target.cpp" "${protocol[@]}" -o "$binary"
  corpus="$work/$target/corpus"
  rm -rf "$corpus" && mkdir -p "$corpus"
  cp "$here/corpus/$target"/* "$corpus/"
  echo "fuzz_$target: ${seconds}s from $(ls "$corpus" | wc -l) seeds"
  # Replay every kept case first: regressions fail here, before any new search.
  "$binary" "$here/corpus/$target"/* >"$work/$target/replay.log" 2>&1 || {
    echo "fuzz_$target: a kept case fails"; tail -20 "$work/$target/replay.log"; status=1; continue; }
  if ! (cd "$work/$target" && "$binary" -max_total_time="$seconds" -print_final_stats=1 \
          "$corpus" >"$work/$target/fuzz.log" 2>&1); then
    echo "fuzz_$target: FAILED"; tail -30 "$work/$target/fuzz.log"; status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "$work/$target/fuzz.log" | tail -2
  fi
done
exit "$status"
