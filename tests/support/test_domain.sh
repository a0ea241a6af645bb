# Sourced by test scripts whose DDS participants meet on this host's loopback:
# sets `domain` to a DDS domain no other test process uses, by
# tests/support/test_domain.hpp's scheme (test_domain.py is the same for
# Python): a lock file per domain, held on file descriptor 9 while the script
# lives (and any program it starts without `9>&-`), so scripts and the C++ and
# Python tests that ctest runs beside them do not meet.
domain=
for ((domain_try = 0; domain_try < 200; domain_try++)); do
  domain_candidate=$((10 + ($$ + domain_try) % 200))
  exec 9>"/tmp/dh3-test-domain-$domain_candidate.lock"
  if flock -n 9; then domain=$domain_candidate; break; fi
  exec 9>&-
done
unset domain_try domain_candidate
[[ -n $domain ]] || { echo "no free DDS domain among 10-209" >&2; exit 1; }
