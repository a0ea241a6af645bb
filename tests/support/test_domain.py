"""The DDS domain of a Python test process: tests/support/test_domain.hpp's
scheme (a lock file per domain, held while the process lives), so Python and
C++ tests run at once do not meet."""

import fcntl
import os

_domain_lock = None


def pick_domain() -> int:
    """A DDS domain no other test process uses."""
    global _domain_lock
    first, count = 10, 200
    start = os.getpid() % count
    for i in range(count):
        candidate = first + (start + i) % count
        lock = open(f"/tmp/dh3-test-domain-{candidate}.lock", "a+")
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            lock.close()
            continue
        _domain_lock = lock  # kept open: the lock ends with the process
        return candidate
    return first + start
