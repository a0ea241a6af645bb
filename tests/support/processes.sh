# Sourced by the test and benchmark scripts that start processes. On exit,
# however the script ends: every PID in the array `pids` is killed and waited
# for, the function extra_cleanup runs if the script defines one, and the
# folder $work, if set, is removed.
pids=()

kill_and_clean_up() {
  local pid
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  if declare -F extra_cleanup >/dev/null; then extra_cleanup; fi
  if [[ -n ${work:-} ]]; then rm -rf "$work"; fi
}
trap kill_and_clean_up EXIT
