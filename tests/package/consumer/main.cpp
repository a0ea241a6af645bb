// drive_hand HAND POSITION: initializes the hand and moves it to POSITION
// percent; exit 0 once the hand's status reports it there.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <dh3/client.hpp>
#include <string>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: drive_hand HAND POSITION\n");
    return 2;
  }
  const int target = std::atoi(argv[2]);
  dh3::Client client(dh3::ClientOptions{});
  auto hand = client.wait_for_hand(argv[1], std::chrono::seconds(30));
  if (!hand) {
    std::fprintf(stderr, "no hand %s: %s\n", argv[1], hand.message().c_str());
    return 1;
  }
  const auto failed = [](const char* what, const dh3::Reply& reply) {
    if (reply) return false;
    std::fprintf(stderr, "%s: %s: %s\n", what, std::string(dh3::to_string(reply.code)).c_str(),
                 reply.message.c_str());
    return true;
  };
  if (failed("initialize", hand->initialize(std::chrono::seconds(30))) ||
      failed("move", hand->move_to(target, std::chrono::seconds(30)))) {
    return 1;
  }
  const auto there = hand->wait_until(
      [target](const dh3::HandStatus& s) { return s.position == target; }, std::chrono::seconds(30));
  if (!there) {
    std::fprintf(stderr, "the hand did not report position %d\n", target);
    return 1;
  }
  std::printf("%s at %d\n", argv[1], there->position);
  return 0;
}
