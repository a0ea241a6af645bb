#pragma once
// dh3ctl: the command line on top of libdh3client. run() is the whole
// program apart from signal set-up, so tests can run it in-process.

#include <atomic>
#include <ostream>

namespace dh3::ctl {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailed = 1;  ///< the command failed; the reason is on stderr
inline constexpr int kExitUsage = 2;   ///< bad command line, or a confirmation missing

/// Runs dh3ctl. `interrupted` ends the commands that run until stopped
/// (status --watch, events); main() sets it on SIGINT and SIGTERM.
int run(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
        const std::atomic<bool>& interrupted);

}  // namespace dh3::ctl
