// restrict_af: runs a command the way systemd's RestrictAddressFamilies= would,
// and optionally a SystemCallFilter=~ deny list, so the unit file's lists can
// be tested without systemd as PID 1.
//
//   restrict_af AF_UNIX,AF_INET,AF_CAN [--deny-syscalls NR,NR,...] -- COMMAND [ARGS...]
//
// Installs a seccomp filter (after PR_SET_NO_NEW_PRIVS) under which socket(2)
// with any other address family fails with EAFNOSUPPORT, which is what systemd
// does; socketpair(2) and everything else are untouched, as with systemd.
// The system calls numbered in --deny-syscalls (x86-64 numbers) fail with
// EPERM, as under the units' SystemCallErrorNumber=EPERM.

#include <linux/audit.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Family {
  const char* name;
  int value;
};

constexpr Family kFamilies[] = {
    {"AF_UNIX", AF_UNIX},       {"AF_INET", AF_INET},     {"AF_INET6", AF_INET6},
    {"AF_NETLINK", AF_NETLINK}, {"AF_PACKET", AF_PACKET}, {"AF_CAN", AF_CAN},
};

bool parse_families(const std::string& list, std::vector<int>& out) {
  std::stringstream stream(list);
  std::string item;
  while (std::getline(stream, item, ',')) {
    bool known = false;
    for (const auto& family : kFamilies) {
      if (item == family.name) {
        out.push_back(family.value);
        known = true;
      }
    }
    if (!known) {
      std::fprintf(stderr, "restrict_af: unknown address family '%s'\n", item.c_str());
      return false;
    }
  }
  return !out.empty();
}

sock_filter statement(unsigned short code, unsigned int k) {
  return sock_filter{code, 0, 0, k};
}
sock_filter jump(unsigned short code, unsigned int k, unsigned char if_true,
                 unsigned char if_false) {
  return sock_filter{code, if_true, if_false, k};
}

bool parse_numbers(const std::string& list, std::vector<unsigned int>& out) {
  std::stringstream stream(list);
  std::string item;
  while (std::getline(stream, item, ',')) {
    if (item.empty() || item.find_first_not_of("0123456789") != std::string::npos) {
      std::fprintf(stderr, "restrict_af: '%s' is not a system call number\n", item.c_str());
      return false;
    }
    out.push_back(static_cast<unsigned int>(std::stoul(item)));
  }
  return true;
}

bool install_filter(const std::vector<int>& allowed, const std::vector<unsigned int>& denied) {
  std::vector<sock_filter> program;
  // Another architecture's system call numbers mean something else: refuse
  // them all rather than filter the wrong call.
  program.push_back(statement(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, arch)));
  program.push_back(jump(BPF_JMP | BPF_JEQ | BPF_K, AUDIT_ARCH_X86_64, 1, 0));
  program.push_back(statement(BPF_RET | BPF_K, SECCOMP_RET_KILL_PROCESS));
  program.push_back(statement(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, nr)));
  for (const unsigned int number : denied) {
    program.push_back(jump(BPF_JMP | BPF_JEQ | BPF_K, number, 0, 1));
    program.push_back(statement(BPF_RET | BPF_K, SECCOMP_RET_ERRNO | (EPERM & SECCOMP_RET_DATA)));
  }
  program.push_back(jump(BPF_JMP | BPF_JEQ | BPF_K, SYS_socket, 1, 0));
  program.push_back(statement(BPF_RET | BPF_K, SECCOMP_RET_ALLOW));
  // socket(domain, ...): the low 32 bits of the first argument.
  program.push_back(statement(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, args[0])));
  for (const int family : allowed) {
    program.push_back(jump(BPF_JMP | BPF_JEQ | BPF_K, static_cast<unsigned int>(family), 0, 1));
    program.push_back(statement(BPF_RET | BPF_K, SECCOMP_RET_ALLOW));
  }
  program.push_back(
      statement(BPF_RET | BPF_K, SECCOMP_RET_ERRNO | (EAFNOSUPPORT & SECCOMP_RET_DATA)));

  sock_fprog fprog{static_cast<unsigned short>(program.size()), program.data()};
  if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0) {
    std::perror("restrict_af: PR_SET_NO_NEW_PRIVS");
    return false;
  }
  if (syscall(SYS_seccomp, SECCOMP_SET_MODE_FILTER, 0, &fprog) != 0) {
    std::perror("restrict_af: seccomp");
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<unsigned int> denied;
  int separator = 2;
  if (argc > 4 && std::strcmp(argv[2], "--deny-syscalls") == 0) {
    if (!parse_numbers(argv[3], denied)) return 2;
    separator = 4;
  }
  if (argc < separator + 2 || std::strcmp(argv[separator], "--") != 0) {
    std::fprintf(stderr,
                 "usage: restrict_af AF_UNIX,AF_INET,... [--deny-syscalls NR,...] -- COMMAND "
                 "[ARGS...]\n");
    return 2;
  }
  std::vector<int> allowed;
  if (!parse_families(argv[1], allowed)) return 2;
  if (!install_filter(allowed, denied)) return 1;
  execvp(argv[separator + 1], argv + separator + 1);
  std::fprintf(stderr, "restrict_af: cannot run %s: %s\n", argv[separator + 1],
               std::strerror(errno));
  return 127;
}
