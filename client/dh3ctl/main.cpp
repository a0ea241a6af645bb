// dh3ctl: drive DH-3 hands on a DDS domain from the command line.

#include <atomic>
#include <csignal>
#include <iostream>

#include "commands.hpp"

namespace {
std::atomic<bool> g_interrupted{false};
extern "C" void on_signal(int /*signal*/) {
  g_interrupted = true;
}
}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  return dh3::ctl::run(argc, argv, std::cout, std::cerr, g_interrupted);
}
