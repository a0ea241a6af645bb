// event_watcher: prints every hand event on the domain (or one hand's) as it
// happens, with an event callback of libdh3client. Ctrl-C to stop.
//
//   event_watcher                 every hand on domain 0
//   event_watcher --domain 5 cell/bus0/2

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>

#include "dds_options.hpp"
#include "dh3/client.hpp"

namespace {
std::atomic<bool> g_stop{false};
extern "C" void on_signal(int /*signal*/) {
  g_stop = true;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"event_watcher: print DH-3 hand events (a libdh3client example)"};
  dh3::ClientOptions options;
  std::string hand_spec;
  add_dds_options(app, options);
  app.add_option("HAND", hand_spec, "only this hand (default: every hand)");
  CLI11_PARSE(app, argc, argv);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  options.participant_name = "event_watcher";
  dh3::Client client(options);
  if (!client.connected()) {
    std::fprintf(stderr, "event_watcher: %s\n", client.error().c_str());
    return 1;
  }
  std::optional<dh3::HandAddress> only;
  if (!hand_spec.empty()) {
    auto hand = client.wait_for_hand(hand_spec);
    if (!hand) {
      std::fprintf(stderr, "event_watcher: %s\n", hand.message().c_str());
      return 1;
    }
    only = hand->address();
  }
  // The callback runs on the client's own thread, one event at a time.
  dh3::Subscription subscription = client.subscribe(
      [](const dh3::HandEvent& e) {
        // An ending motion's position is where it stopped, once read.
        const std::string position = e.position ? std::to_string(*e.position) : "not read yet";
        std::printf("%s %s position %s target %d%s%s\n", e.hand.to_string().c_str(),
                    std::string(to_string(e.kind)).c_str(), position.c_str(), e.target,
                    e.message.empty() ? "" : ": ", e.message.c_str());
        std::fflush(stdout);
      },
      only);
  // Events are a stream: they reach a subscriber once the service has
  // matched it. A ready service has; until then events could pass unseen.
  if (auto service = client.wait_for_service(only ? only->service : ""); !service) {
    std::fprintf(stderr, "event_watcher: %s; watching anyway\n", service.message().c_str());
  }
  std::printf("watching events (Ctrl-C to stop)\n");
  std::fflush(stdout);
  while (!g_stop) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  subscription.unsubscribe();  // after this no callback runs: safe to leave
  return 0;
}
