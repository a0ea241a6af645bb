#pragma once
// The DDS domain of a test process. ctest runs every test in a process of its
// own, often several at once, and other checkouts may run theirs on the same
// machine: two tests that share a domain see each other's samples (a request
// that names no service is answered by every service there). The pid picks
// where to start; a lock file per domain, held while the process lives, makes
// the choice unique among the processes that use this function.

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <string>

namespace dh3::test {

inline int test_domain() {
  static const int domain = [] {
    constexpr int kFirst = 10;
    constexpr int kCount = 200;
    const int start = static_cast<int>(::getpid() % kCount);
    for (int i = 0; i < kCount; ++i) {
      const int candidate = kFirst + (start + i) % kCount;
      const std::string path = "/tmp/dh3-test-domain-" + std::to_string(candidate) + ".lock";
      const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
      if (fd < 0) continue;
      // Kept open on success: the lock ends with the process. O_CLOEXEC: the
      // test's child processes (service, sim, dh3ctl) do not hold it.
      if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return candidate;
      ::close(fd);
    }
    return kFirst + start;  // every domain taken: share one rather than fail
  }();
  return domain;
}

}  // namespace dh3::test
