# The tests the AddressSanitizer + UBSan run selects, for tests/sanitize/run-sanitized.sh
# (which runs them sanitized) and tests/run-all.sh (which runs every other test in the plain
# build, so each C++ test runs once, in its stricter form). Sourced, not run.
#
# The C++ tests: the labels below.
address_labels='^(unit|integration|reliability|soak)$'
# Left out of them (and so run in the plain build):
# <program>_NOT_BUILT: what ctest lists for a test program the sanitized
#   build did not build (run-sanitized.sh builds only the programs it runs).
# kernel.*: run in user-mode Linux, whose root is this machine's files; the
#   plain build's programs run there.
# fuzz.*: the fuzz targets are built by clang with ASan+UBSan already.
# install.*: builds and links an out-of-tree program against the
#   installed package; a packaging check, not code that runs.
# layering.*, client.header_examples*, docs.*, style.*: compile checks and
#   source readers.
# reliability.client_burst: a load test (dozens of processes at once beside
#   busy loops); its programs' code runs under the sanitizers in the other
#   tests, and sanitized it would measure the sanitizers.
# vendor.*, ros2.* (the scripts; the Ros2* C++ tests run sanitized): Cyclone
#   DDS's participant, npm's encoder, tshark; interoperability is a property
#   of the wire, checked by the main build.
# The Python module's tests and the page in Chromium are not C++ (dh3-web's
#   C++ runs sanitized in test_web_service).
address_left_out='(_NOT_BUILT$|^fuzz\.|^install\.|^layering\.|^client\.header_examples|^docs\.|^style\.|^kernel\.|^vendor\.|^ros2\.|^reliability\.client_burst$|^web\.browser$)'
