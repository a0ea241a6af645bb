// pick_loop: grasps and releases one hand again and again, the way a robot
// cell's program would drive it through libdh3client.
//
//   pick_loop --hand cell/bus0/1 --cycles 10 --force 40
//   pick_loop --domain 5 --interface 192.168.1.20 --udp-only --hand 1
//   pick_loop --security-dir /etc/dh3/pki --security-identity operator --hand 1
//
// Exit 0 when every command succeeded (a grasp that closed on nothing is a
// success: MISSED is an answer, not an error), 1 otherwise.

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "dds_options.hpp"
#include "dh3/client.hpp"

namespace {

bool check(const char* what, const dh3::Reply& reply) {
  if (reply) return true;
  std::fprintf(stderr, "pick_loop: %s: %s: %s\n", what, std::string(to_string(reply.code)).c_str(),
               reply.message.c_str());
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pick_loop: grasp and release a DH-3 hand in a loop (a libdh3client example)"};
  dh3::ClientOptions options;
  std::string hand_spec;
  int cycles = 3;
  int force = 40;
  int open_position = 100;
  double timeout_s = 20.0;
  add_dds_options(app, options);
  app.add_option("--hand", hand_spec, "the hand: SERVICE/BUS/ID, BUS/ID, ID or NAME")->required();
  app.add_option("--cycles", cycles, "grasp-release cycles (default 3)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--force", force, "closing force, 20-100 percent (default 40)");
  app.add_option("--open", open_position, "position to release to (default 100)");
  app.add_option("-t,--timeout", timeout_s, "seconds for each step (default 20)")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  options.participant_name = "pick_loop";
  options.default_timeout = std::chrono::milliseconds(static_cast<long long>(timeout_s * 1000.0));
  dh3::Client client(options);
  if (!client.connected()) {
    std::fprintf(stderr, "pick_loop: %s\n", client.error().c_str());
    return 1;
  }
  auto hand = client.wait_for_hand(hand_spec);
  if (!hand) {
    std::fprintf(stderr, "pick_loop: %s\n", hand.message().c_str());
    return 1;
  }
  std::printf("hand %s\n", hand->address().to_string().c_str());

  // Initialize only if needed: re-initializing a hand that holds something
  // would open it.
  const auto status = hand->status();
  if (!status || !status->initialized) {
    if (!check("initialize", hand->initialize())) return 1;
    std::printf("initialized\n");
  }
  int grasped = 0;
  for (int cycle = 1; cycle <= cycles; ++cycle) {
    const dh3::Reply grasp = hand->grasp(force);
    if (!check("grasp", grasp)) return 1;
    if (grasp.grasp == dh3::GraspOutcome::grasped) ++grasped;
    std::printf("cycle %d: %s at position %d\n", cycle, std::string(to_string(grasp.grasp)).c_str(),
                grasp.value);
    if (!check("release", hand->release(open_position))) return 1;
    std::fflush(stdout);
  }
  std::printf("done: %d cycles, %d grasped\n", cycles, grasped);
  return 0;
}
