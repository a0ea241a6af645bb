# Sourced by tests/run-all.sh: what failed, in a few lines per failure, for the
# end of a long log, where whoever reads only its tail looks.

# Prints each failed test of the ctest log $1 (Testing/Temporary/LastTest.log)
# under the heading $2, with the first lines that say why: GoogleTest's
# failure lines, a script's FAIL or error lines, or the last lines of output.
failed_tests_in() {
  local log=$1 heading=$2
  [[ -f $log ]] || return 0
  awk -v heading="$heading" '
    function flush(   i, shown) {
      if (!failed) return
      if (!printed_heading) { print "-- " heading; printed_heading = 1 }
      print "   " name
      shown = 0
      for (i = 1; i <= n && shown < 8; ++i) {
        if (lines[i] ~ /Failure|Expected|Which is|Value of|Actual:|FAIL|[Ee]rror|Timeout|Exception|SUMMARY/) {
          print "     " substr(lines[i], 1, 200); ++shown
        }
      }
      for (i = (n > 4 ? n - 3 : 1); shown == 0 && i <= n; ++i) print "     " substr(lines[i], 1, 200)
    }
    / Test: / { flush(); name = $0; sub(/^[0-9]+\/[0-9]+ Test: /, "", name); n = 0; failed = 0; output = 1; next }
    /^<end of output>/ { output = 0; next }
    /^Test Failed/ { failed = 1; next }
    /^Test Passed|^Test time = / { next }
    output { lines[++n] = $0 }
    END { flush() }
  ' "$log"
}

# Prints the kind, the first frames and the summary line of each sanitizer
# report in the folder $1.
sanitizer_reports_in() {
  local folder=$1 report
  for report in "$folder"/*; do
    [[ -f $report ]] || continue
    echo "-- $(basename "$report")"
    grep -m 1 -E '(WARNING|ERROR): ' "$report" | sed 's/^/   /' || true
    grep -m 8 -E '^ +#[0-9]+ ' "$report" | cut -c1-200 | sed 's/^/   /' || true
    grep -m 1 '^SUMMARY: ' "$report" | sed 's/^/   /' || true
  done
}
