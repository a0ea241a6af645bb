#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UBSan) and runs
# each for a bounded time on a copy of its seed corpus.
#   tests/fuzz/run-fuzz.sh WORK_DIR [SECONDS_PER_TARGET [IDL_GENERATED_DIR [TARGET...]]]
# TARGETs: stream_decoder, payload, request_validation (default: all three).
# stream_decoder, payload: seeds are the spec's frames (tests/fuzz/corpus/).
# request_validation: needs the C++ fastddsgen generated from idl/ (the main
# build's BUILD/idl/generated); its seeds are real requests serialized by
# make_request_seeds, plus the kept cases in tests/fuzz/corpus/request_validation/.
# Exit 77 (ctest: skipped) with the reason when clang or libFuzzer is missing.
# A crash leaves its input in WORK_DIR/<target>/; keep it as a regression case
# by copying it into tests/fuzz/corpus/<target>/ once the bug is fixed.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
work=${1:?work directory}
seconds=${2:-20}
generated=${3:-}
targets=("${@:4}")
[[ ${#targets[@]} -gt 0 ]] || targets=(stream_decoder payload request_validation)
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

flags=(-std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all)
for layer in base protocol bus hand dds; do flags+=(-I "$root/service/$layer/include"); done
flags+=(-I "$root/service/dds/src")  # the request validation is private to the DDS side
protocol=("$root"/service/protocol/src/*.cpp)
status=0

# fuzz TARGET: replays the kept cases, then searches from the corpus in
# WORK_DIR/TARGET/corpus for $seconds.
fuzz() {
  local target=$1 binary="$work/fuzz_$1" corpus="$work/$1/corpus"
  local kept=("$here/corpus/$target"/*)
  echo "fuzz_$target: ${seconds}s from $(ls "$corpus" | wc -l) seeds"
  # Replay every kept case first: regressions fail here, before any new search.
  if [[ -e ${kept[0]} ]]; then
    "$binary" "${kept[@]}" >"$work/$target/replay.log" 2>&1 || {
      echo "fuzz_$target: a kept case fails"; tail -20 "$work/$target/replay.log"; status=1; return; }
  fi
  if ! (cd "$work/$target" && "$binary" -max_total_time="$seconds" -print_final_stats=1 \
          "$corpus" >"$work/$target/fuzz.log" 2>&1); then
    echo "fuzz_$target: FAILED"; tail -30 "$work/$target/fuzz.log"; status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "$work/$target/fuzz.log" | tail -2
  fi
}

# fresh_corpus TARGET: WORK_DIR/TARGET/corpus, empty but for the kept cases.
fresh_corpus() {
  local corpus="$work/$1/corpus"
  rm -rf "$corpus" && mkdir -p "$corpus"
  if compgen -G "$here/corpus/$1/*" >/dev/null; then cp "$here/corpus/$1"/* "$corpus/"; fi
}

# The request as the service receives it: generated type support, Fast CDR and
# Fast DDS's payload type (linked from the system's libraries), the service's
# DDS-side validation and the hand layer's command checks.
build_request_validation() {
  if [[ -z $generated || ! -f $generated/dh3/contract/dh3PubSubTypes.cxx ]]; then
    echo "fuzz_request_validation: no generated IDL code in '$generated' (build the project first)"
    return 1
  fi
  local idl=(-I "$generated" -I "$generated/dh3/contract" -I "$root/idl/include")
  local idl_sources=("$generated/dh3/contract/dh3.cxx" "$generated/dh3/contract/dh3PubSubTypes.cxx"
    "$root"/idl/src/names.cpp "$root"/idl/src/value_ranges.cpp)
  local libs=(-lfastrtps -lfastcdr -lfmt)
  "$cxx" "${flags[@]}" "${idl[@]}" "$here/fuzz_request_validation.cpp" "${idl_sources[@]}" \
    "$root"/service/dds/src/request_validation.cpp "$root"/service/dds/src/conversions.cpp \
    "$root"/service/dds/src/hand_directory.cpp "$root"/service/hand/src/command_validation.cpp \
    "$root"/service/hand/src/hand_types.cpp "${protocol[@]}" "${libs[@]}" \
    -o "$work/fuzz_request_validation" || return 1
  # The contract's sources include base's headers (Result).
  "$cxx" -std=c++20 -O1 -I "$root/service/base/include" "${idl[@]}" "$here/make_request_seeds.cpp" \
    "${idl_sources[@]}" "${libs[@]}" -o "$work/make_request_seeds" || return 1
  fresh_corpus request_validation
  "$work/make_request_seeds" "$work/request_validation/corpus" || return 1
}

for target in "${targets[@]}"; do
  case $target in
    stream_decoder | payload)
      "$cxx" "${flags[@]}" "$here/fuzz_$target.cpp" "${protocol[@]}" -o "$work/fuzz_$target"
      fresh_corpus "$target" ;;
    request_validation)
      build_request_validation || { status=1; continue; } ;;
    *)
      echo "unknown fuzz target $target"; status=1; continue ;;
  esac
  fuzz "$target"
done
exit "$status"
