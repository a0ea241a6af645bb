# Sourced by tests/run-all.sh: what failed, in a few lines per failure, for the
# end of a long log, where whoever reads only its tail looks.

# Prints each failed test in the ctest console output $1 (run with
# --output-on-failure) under the heading $2, with the first lines of its output
# that say why: GoogleTest's failure lines, a script's FAIL or error lines, or
# else its last lines. Not ctest's LastTest.log: a test that runs `ctest -N` in
# the same tree (docs.examples) rewrites that file while the run goes on.
failed_tests_in() {
  local console=$1 heading=$2
  [[ -f $console ]] || return 0
  awk -v heading="$heading" '
    function flush(   i, shown) {
      if (name == "") return
      if (!printed_heading) { print "-- " heading; printed_heading = 1 }
      print "   " name
      shown = 0
      for (i = 1; i <= n && shown < 8; ++i) {
        if (lines[i] ~ /Failure|Expected|Which is|Value of|Actual:|FAIL|[Ee]rror|Timeout|Exception|SUMMARY/) {
          print "     " substr(lines[i], 1, 200); ++shown
        }
      }
      for (i = (n > 4 ? n - 3 : 1); shown == 0 && i <= n; ++i) print "     " substr(lines[i], 1, 200)
      name = ""
    }
    /^ *[0-9]+\/[0-9]+ Test +#[0-9]+: / || /^ *Start +[0-9]+: / || /^[0-9]+% tests passed/ {
      flush()
      if ($0 ~ /\*\*\*(Failed|Timeout|Exception)|\(Failed\)|\*\*\*Not Run/) {
        name = $0
        sub(/^ *[0-9]+\/[0-9]+ Test +#[0-9]+: /, "", name)
        sub(/ \.+ *\*\*\*.*/, "", name)
        n = 0
      }
      next
    }
    name != "" { lines[++n] = $0 }
    END { flush() }
  ' "$console"
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
