/* Preloaded into user-mode Linux by uml-run.sh. Debian 12's UML kernel (6.1)
 * saves and restores its processes' FPU state with PTRACE_GETREGSET and
 * PTRACE_SETREGSET of NT_X86_XSTATE in a buffer of the legacy area, the
 * header and AVX (832 bytes). A host whose XSAVE area is larger (AVX-512,
 * AMX) refuses a PTRACE_SETREGSET of any other size than its own (EFAULT),
 * and the kernel dies at its first process: "ptrace set fp regs failed,
 * errno = 14". This widens both calls to the host's size: a read hands UML
 * the part it asked for, a write puts UML's part over the process's current
 * state. The components beyond it (AVX-512's, AMX's) are then not switched
 * between the threads of one guest process, so uml-run.sh keeps the guest's
 * C library off them (GLIBC_TUNABLES). Where UML's buffer fits the host's
 * area every call goes through unchanged. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <elf.h>
#include <stdarg.h>
#include <string.h>
#include <sys/ptrace.h>
#include <sys/types.h>
#include <sys/uio.h>

typedef long (*ptrace_function)(int, pid_t, void *, void *);

long ptrace(enum __ptrace_request request, ...) {
  static ptrace_function real;
  static __thread unsigned char host_area[65536] __attribute__((aligned(64)));
  if (!real) real = (ptrace_function)dlsym(RTLD_NEXT, "ptrace");
  va_list args;
  va_start(args, request);
  pid_t pid = va_arg(args, pid_t);
  void *addr = va_arg(args, void *);
  void *data = va_arg(args, void *);
  va_end(args);
  if ((request != PTRACE_GETREGSET && request != PTRACE_SETREGSET) ||
      (long)addr != NT_X86_XSTATE || !data) {
    return real(request, pid, addr, data);
  }
  struct iovec *asked = data;
  struct iovec full = {host_area, sizeof host_area};
  if (real(PTRACE_GETREGSET, pid, addr, &full) != 0 || full.iov_len <= asked->iov_len) {
    return real(request, pid, addr, data);
  }
  if (request == PTRACE_GETREGSET) {
    memcpy(asked->iov_base, host_area, asked->iov_len);
    return 0;
  }
  memcpy(host_area, asked->iov_base, asked->iov_len);
  return real(PTRACE_SETREGSET, pid, addr, &full);
}
