// Writes the seed corpus of fuzz_request_validation: real command requests,
// serialized by the same generated type support a client writes them with,
// one file each. Built and run by run-fuzz.sh, so the seeds always match the
// IDL as it is now.
//   make_request_seeds DIR

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "dh3/contract/dh3PubSubTypes.h"

namespace {

using dh3::msg::CommandType;

dh3::msg::CommandRequest request(CommandType command, std::int32_t value, std::uint16_t can_id,
                                 const std::string& bus = "box", std::uint16_t reg = 0,
                                 std::uint32_t timeout_ms = 0) {
  dh3::msg::CommandRequest r;
  r.client_id("0f1e2d3c4b5a69788796a5b4");
  r.request_seq(42);
  r.hand().service("dh3");
  r.hand().bus(bus);
  r.hand().can_id(can_id);
  r.command(command);
  r.value(value);
  r.register_code(reg);
  r.timeout_ms(timeout_ms);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_request_seeds DIR\n");
    return 2;
  }
  using namespace dh3::msg;
  const std::vector<CommandRequest> seeds{
      request(INITIALIZE, 0, 1),
      request(MOVE, 60, 1),
      request(SET_CLOSING_FORCE, 30, 2),
      request(SET_OPENING_FORCE, 100, 3),
      request(ROTATE, 67, 1),
      request(READ_REGISTER, 0, 1, "box", 0x0602),
      request(READ_REGISTER, 0, 0, "box", 0x1201),
      request(READ_REGISTER, 0, 2, "box", 0x1301, 500),
      request(SET_CAN_ID, 5, 0),
      request(SET_CAN_ID, 7, 1),
      request(SET_BAUD_RATE, 2, 1),
      request(ENABLE_INIT_FEEDBACK, 0, 1),
      request(GRASP, 40, 2, "box", 0, 5000),
      request(RELEASE, 100, 2),
      request(STOP, 0, 3),
      request(SCAN, 0, 0, "spare"),
      request(ACQUIRE_LEASE, 2000, 1),
      request(RENEW_LEASE, 600000, 1),
      request(RELEASE_LEASE, 0, 1),
      request(MOVE, 101, 1),                        // out of range
      request(MOVE, 50, 9),                         // no such hand
      request(MOVE, 50, 1, "nowhere"),              // no such bus
      request(READ_REGISTER, 0, 1, "box", 0x0999),  // not a register
      request(static_cast<CommandType>(16), 0, 1),  // not a command
  };
  CommandRequestPubSubType type;
  int index = 0;
  for (auto seed : seeds) {
    eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&seed)());
    if (!type.serialize(&seed, &payload)) {
      std::fprintf(stderr, "make_request_seeds: seed %d does not serialize\n", index);
      return 1;
    }
    char name[32];
    std::snprintf(name, sizeof name, "/request_%02d", index++);
    std::ofstream(argv[1] + std::string(name), std::ios::binary)
        .write(reinterpret_cast<const char*>(payload.data), payload.length);
  }
  return 0;
}
