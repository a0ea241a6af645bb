#pragma once
// How a dh3 program is told to stop: SIGINT or SIGTERM, taken on its main
// thread by sigwait() (or sigtimedwait()) rather than by a handler.

#include <csignal>

namespace dh3 {

/// Blocks SIGINT and SIGTERM in the calling thread, and so in every thread it
/// starts later (none of them is interrupted), and returns the set to wait on.
/// Call it first in main(), before any thread starts.
[[nodiscard]] sigset_t block_stop_signals();

}  // namespace dh3
