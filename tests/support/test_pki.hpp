#pragma once
// A test PKI for a test suite: deploy/security/make-test-pki.sh run into a new
// temporary directory, granting the suite's DDS domain. Making keys is the
// slow part, so a suite makes one in SetUpTestSuite and removes it in
// TearDownTestSuite.

#include <sys/wait.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "support/process.hpp"

namespace dh3::test {

/// The PKI's directory, or empty (and nothing left behind) if it could not
/// be made. `tag` names the directory; `extra` are more script arguments.
inline std::string make_test_pki(const std::string& script, int domain, const std::string& tag,
                                 std::vector<std::string> extra = {}) {
  namespace fs = std::filesystem;
  std::string dir = (fs::temp_directory_path() / ("dh3-" + tag + "-pki-XXXXXX")).string();
  if (::mkdtemp(dir.data()) == nullptr) return {};
  extra.insert(extra.end(), {"--domains", std::to_string(domain), dir});
  Process made(script, extra, Process::Stdin::dev_null);
  const auto status = made.wait_exit(std::chrono::seconds(120));
  if (status && WIFEXITED(*status) && WEXITSTATUS(*status) == 0) return dir;
  std::error_code ignored;
  fs::remove_all(dir, ignored);
  return {};
}

inline void remove_test_pki(const std::string& dir) {
  std::error_code ignored;
  if (!dir.empty()) std::filesystem::remove_all(dir, ignored);
}

}  // namespace dh3::test
