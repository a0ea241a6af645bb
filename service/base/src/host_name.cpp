#include "dh3/base/host_name.hpp"

#include <unistd.h>

#include <cerrno>

namespace dh3 {

std::string host_name() {
  char name[256] = {};
  if (gethostname(name, sizeof name - 1) != 0) return {};
  return name;
}

std::string program_at_host(const std::string& program) {
  if (program.find('@') != std::string::npos) return program;
  std::string shown = program.empty() ? std::string(program_invocation_short_name) : program;
  const std::string host = host_name();
  return host.empty() ? shown : shown + "@" + host;
}

}  // namespace dh3
