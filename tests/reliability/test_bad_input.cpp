// Bad input over raw DDS: thousands of random requests over the IDL types,
// floods beyond a hand's queue bound, administrative commands the service does
// not allow. Every request addressed to the service gets exactly one reply with
// a code that fits it, the service stays up with bounded memory, and every
// frame it sends to the box is one the protocol document allows.
//
// The random requests are seeded; the seed is printed, and DH3_RANDOM_SEED=N
// replays a run (DH3_RANDOM_REQUESTS=N changes how many are sent).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <climits>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fstream>
#include <map>
#include <random>
#include <set>

#include "reliability_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::AnyOf;
using ::testing::Eq;
using ::testing::StartsWith;

// ---------------------------------------------------------------------------
// The protocol document's registers (docs/dh3-protocol.md),
// written out here rather than taken from the service's codec.

struct SpecRegister {
  std::uint16_t code;
  bool writable;  ///< by this service as configured (administrative: never)
  std::int32_t min;
  std::int32_t max;
};

constexpr SpecRegister kSpecRegisters[] = {
    {0x0801, true, 0, 0},     // initialization feedback: enabled by writing 0
    {0x0802, true, 0, 0},     // initialize
    {0x0502, true, 20, 100},  // closing force
    {0x0503, true, 20, 100},  // opening force
    {0x0602, true, 0, 100},   // position
    {0x0702, true, 0, 100},   // rotation
    {0x0F01, false, 0, 0},    // grip status
    {0x0F02, false, 0, 0},    // rotation status
    {0x1201, false, 1, 255},  // CAN ID: administrative
    {0x1301, false, 0, 0},    // firmware version
    {0x1401, false, 0, 5},    // baud rate: administrative
};

const SpecRegister* spec_register(std::uint16_t code) {
  for (const auto& reg : kSpecRegisters) {
    if (reg.code == code) return &reg;
  }
  return nullptr;
}

/// Why a 14-byte frame the service sent breaks the document (or this
/// service's configuration: hands 1-3, no administration), empty if it does not.
std::string spec_violation(const std::uint8_t* f) {
  if (f[0] != 0xFF || f[1] != 0xFE || f[2] != 0xFD || f[3] != 0xFC) return "bad header";
  if (f[13] != 0xFB) return "bad frame end";
  if (f[8] != 0x00) return "reserve byte not 0";
  const std::uint8_t id = f[4];
  const auto code = static_cast<std::uint16_t>(f[5] << 8 | f[6]);
  const std::uint8_t rw = f[7];
  const auto data = static_cast<std::int32_t>(
      static_cast<std::uint32_t>(f[9]) | static_cast<std::uint32_t>(f[10]) << 8 |
      static_cast<std::uint32_t>(f[11]) << 16 | static_cast<std::uint32_t>(f[12]) << 24);
  const SpecRegister* reg = spec_register(code);
  if (reg == nullptr) return "function/sub-function not in the document";
  if (rw > 1) return "read/write byte neither 00 nor 01";
  if (id == 0 && code != 0x1201) return "ID 0 for a register other than the CAN ID";
  if (rw == 0) return data == 0 ? "" : "a read with data";
  if (!reg->writable) return "a write to a read-only or administrative register";
  if (id < 1 || id > 3) return "a write to a hand that is not there";
  if (data < reg->min || data > reg->max) return "a written value out of the document's range";
  return "";
}

/// Every frame in `bytes` that breaks the document, with the reason.
std::vector<std::string> spec_violations(const std::vector<std::uint8_t>& bytes) {
  std::vector<std::string> bad;
  if (bytes.size() % 14 != 0) bad.push_back("a partial frame at the end");
  const auto hex = frames_as_hex(bytes);
  for (std::size_t i = 0; i < hex.size(); ++i) {
    const std::string why = spec_violation(bytes.data() + 14 * i);
    if (!why.empty()) bad.push_back(hex[i] + ": " + why);
  }
  return bad;
}

// ---------------------------------------------------------------------------
// What a reply to a request must say, from the contract (idl/dh3.idl limits,
// the documented order of checks), written out apart from the service's own
// range table on purpose: an oracle that shares it cannot catch a wrong range.

using Range = std::pair<std::int64_t, std::int64_t>;

/// The range of a command's value, nullopt for commands that ignore it.
std::optional<Range> value_range(msg::CommandType command) {
  namespace l = limits;
  switch (command) {
    case msg::MOVE:
    case msg::RELEASE:
      return Range{l::POSITION_MIN, l::POSITION_MAX};
    case msg::ROTATE:
      return Range{l::ROTATION_MIN, l::ROTATION_MAX};
    case msg::SET_CLOSING_FORCE:
    case msg::SET_OPENING_FORCE:
    case msg::GRASP:
      return Range{l::FORCE_MIN, l::FORCE_MAX};
    case msg::SET_CAN_ID:
      return Range{l::CAN_ID_MIN, l::CAN_ID_MAX};
    case msg::SET_BAUD_RATE:
      return Range{l::BAUD_INDEX_MIN, l::BAUD_INDEX_MAX};
    case msg::ACQUIRE_LEASE:
    case msg::RENEW_LEASE:
      return Range{l::LEASE_TTL_MIN_MS, l::LEASE_TTL_MAX_MS};
    default:
      return std::nullopt;
  }
}

/// The code the request must get when the contract decides it alone
/// (INVALID_ARGUMENT, UNKNOWN_HAND, DENIED); nullopt when it depends on the
/// hand (OK, BUSY, TIMEOUT, NOT_INITIALIZED, a lease: DENIED ...).
std::optional<msg::ResultCode> decided_code(const msg::CommandRequest& r) {
  const auto command = static_cast<std::uint32_t>(r.command());
  const bool known_command = command <= static_cast<std::uint32_t>(msg::RELEASE_LEASE);
  const bool scan = r.command() == msg::SCAN;
  const std::uint16_t id = r.hand().can_id();
  const bool id_zero_allowed = r.command() == msg::SET_CAN_ID ||
                               (r.command() == msg::READ_REGISTER && r.register_code() == 0x1201);
  const auto range = known_command ? value_range(r.command()) : std::nullopt;
  if (r.client_id().empty() || r.client_id().size() > limits::MAX_NAME_LENGTH ||
      r.hand().service().empty() || !known_command || r.hand().bus().empty() ||
      r.timeout_ms() > limits::REQUEST_TIMEOUT_MAX_MS ||
      (!scan && (id > limits::CAN_ID_MAX || (id == 0 && !id_zero_allowed))) ||
      (range && (r.value() < range->first || r.value() > range->second)) ||
      (r.command() == msg::READ_REGISTER && spec_register(r.register_code()) == nullptr)) {
    return msg::INVALID_ARGUMENT;
  }
  if (r.hand().bus() != "box" || (!scan && id != 0 && id > 3)) return msg::UNKNOWN_HAND;
  if (r.command() == msg::SET_CAN_ID || r.command() == msg::SET_BAUD_RATE) return msg::DENIED;
  return std::nullopt;
}

/// Random requests over the IDL types: any command value (the enum's and
/// beyond), values at and around the limits and anywhere, addresses, client
/// ids and timeouts that are right, wrong, empty or too long.
class RequestGenerator {
 public:
  RequestGenerator(std::uint32_t seed, std::string service, std::string client_id)
      : random_(seed), service_(std::move(service)), client_id_(std::move(client_id)) {}

  msg::CommandRequest next() {
    msg::CommandRequest r;
    r.client_id(
        pick<std::string>({{85, client_id_}, {5, ""}, {5, text(65, 100)}, {5, text(1, 20)}}));
    msg::HandAddress hand;
    hand.service(
        pick<std::string>({{80, service_}, {8, ""}, {6, "other-" + service_}, {6, text(1, 70)}}));
    hand.bus(pick<std::string>({{85, "box"}, {5, ""}, {10, text(1, 70)}}));
    hand.can_id(static_cast<std::uint16_t>(
        chance(80) ? number(1, 3)
                   : pick<std::int64_t>(
                         {{1, 0}, {1, 4}, {1, 255}, {1, 256}, {1, 65535}, {1, number(0, 65535)}})));
    r.hand(hand);
    r.command(static_cast<msg::CommandType>(
        chance(90) ? number(0, 15)
                   : pick<std::int64_t>({{1, 16}, {1, 0x7FFFFFFF}, {1, number(17, 1000)}})));
    r.value(static_cast<std::int32_t>(chance(50)
                                          ? number(-5, 105)
                                          : pick<std::int64_t>({{1, INT_MIN},
                                                                {1, INT_MAX},
                                                                {1, -1},
                                                                {1, 19},
                                                                {1, 20},
                                                                {1, 101},
                                                                {1, 255},
                                                                {1, 256},
                                                                {1, number(99, 600001)},
                                                                {1, number(INT_MIN, INT_MAX)}})));
    static constexpr std::uint16_t kCodes[] = {0x0801, 0x0802, 0x0502, 0x0503, 0x0602, 0x0702,
                                               0x0F01, 0x0F02, 0x1201, 0x1301, 0x1401};
    r.register_code(chance(70) ? kCodes[number(0, std::size(kCodes) - 1)]
                               : static_cast<std::uint16_t>(number(0, 65535)));
    r.timeout_ms(static_cast<std::uint32_t>(chance(75)   ? 0
                                            : chance(70) ? number(1, 3000)
                                                         : number(60001, UINT32_MAX)));
    return r;
  }

 private:
  bool chance(int percent) { return number(1, 100) <= percent; }
  std::int64_t number(std::int64_t min, std::int64_t max) {
    return std::uniform_int_distribution<std::int64_t>(min, max)(random_);
  }
  std::string text(std::size_t min, std::size_t max) {
    std::string s(static_cast<std::size_t>(
                      number(static_cast<std::int64_t>(min), static_cast<std::int64_t>(max))),
                  ' ');
    for (char& c : s) c = static_cast<char>(number(32, 126));
    return s;
  }
  template <typename T>
  T pick(std::initializer_list<std::pair<int, T>> weighted) {
    int total = 0;
    for (const auto& [weight, value] : weighted) total += weight;
    int at = static_cast<int>(number(1, total));
    for (const auto& [weight, value] : weighted) {
      if ((at -= weight) <= 0) return value;
    }
    return weighted.begin()->second;
  }

  std::mt19937_64 random_;
  std::string service_;
  std::string client_id_;
};

std::uint32_t env_number(const char* name, std::uint32_t fallback) {
  const char* text = std::getenv(name);
  return text != nullptr && *text != '\0' ? static_cast<std::uint32_t>(std::stoul(text)) : fallback;
}

/// The service's resident memory (VmRSS), in KiB; 0 if unknown.
long resident_kib(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.starts_with("VmRSS:")) return std::stol(line.substr(6));
  }
  return 0;
}

/// A participant that writes raw bytes as samples of the request topic, as a
/// participant of another vendor or a forger could.
class ForgedRequestWriter {
 public:
  explicit ForgedRequestWriter(int domain) {
    namespace fdds = eprosima::fastdds::dds;
    participant_ = fdds::DomainParticipantFactory::get_instance()->create_participant(
        static_cast<fdds::DomainId_t>(domain), contract::participant_qos("dh3-forger", {}));
    if (participant_ == nullptr) return;
    fdds::TypeSupport type(new RawType());
    type.register_type(participant_);
    auto* topic = participant_->create_topic(topics::COMMAND_REQUEST, type.get_type_name(),
                                             fdds::TOPIC_QOS_DEFAULT);
    auto* publisher = participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    writer_ =
        publisher->create_datawriter(topic, contract::writer_qos(contract::TopicRole::request));
  }
  ~ForgedRequestWriter() {
    if (participant_ == nullptr) return;
    participant_->delete_contained_entities();
    eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->delete_participant(
        participant_);
  }
  ForgedRequestWriter(const ForgedRequestWriter&) = delete;
  ForgedRequestWriter& operator=(const ForgedRequestWriter&) = delete;

  /// Waits until the service's request reader matched this writer.
  bool wait_matched() {
    const auto deadline = std::chrono::steady_clock::now() + kDdsDeadline;
    eprosima::fastdds::dds::PublicationMatchedStatus status;
    while (writer_ != nullptr && std::chrono::steady_clock::now() < deadline) {
      writer_->get_publication_matched_status(status);
      if (status.current_count > 0) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));  // polling, not a wait for time
    }
    return false;
  }

  /// Writes `bytes` as one sample and waits until the readers have it.
  bool write(std::vector<std::uint8_t> bytes) {
    return writer_->write(&bytes) &&
           writer_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(15, 0)) ==
               eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK;
  }

 private:
  /// The request type's name and handling; serializes a byte vector as is.
  class RawType final : public msg::CommandRequestPubSubType {
   public:
    bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
      const auto& bytes = *static_cast<const std::vector<std::uint8_t>*>(data);
      if (bytes.size() > payload->max_size) return false;
      std::copy(bytes.begin(), bytes.end(), payload->data);
      payload->length = static_cast<std::uint32_t>(bytes.size());
      return true;
    }
    std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
      const auto size =
          static_cast<std::uint32_t>(static_cast<const std::vector<std::uint8_t>*>(data)->size());
      return [size] { return size; };
    }
  };

  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
};

/// A request as a Fast DDS client serializes it (encapsulation + CDR body).
std::vector<std::uint8_t> serialized(msg::CommandRequest request) {
  msg::CommandRequestPubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&request)());
  if (!type.serialize(&request, &payload)) return {};
  return {payload.data, payload.data + payload.length};
}

using BadInput = BoxTest;

TEST_F(BadInput, ForgedSamplesOnTheRequestTopicLeaveTheServiceServing) {
  ASSERT_NO_FATAL_FAILURE(start());
  ForgedRequestWriter forger(test_domain());
  ASSERT_TRUE(forger.wait_matched()) << "the service's request reader never matched";
  const auto valid = serialized(client_->request(hand(1), msg::SET_CLOSING_FORCE, 30));
  ASSERT_GT(valid.size(), 20U);

  auto foreign = valid;  // another vendor's XCDR2 encapsulation (CDR2_LE)
  foreign[1] = 0x07;
  auto bad_kind = valid;  // the case the fuzzer found: an encapsulation Fast CDR refuses
  bad_kind[1] = 0x24;
  auto nonzero = valid;  // first encapsulation byte not zero
  nonzero[0] = 0x80;
  const std::vector<std::uint8_t> truncated(valid.begin(), valid.begin() + 14);
  auto huge_string = valid;  // client_id's length says 4 GiB
  std::fill(huge_string.begin() + 4, huge_string.begin() + 8, 0xFF);
  for (const auto& bytes : {foreign, bad_kind, nonzero, truncated, huge_string,
                            std::vector<std::uint8_t>{0x00, 0x01}}) {
    ASSERT_TRUE(forger.write(bytes)) << "a forged sample was not delivered";
    // The service took it: a request written after it is answered.
    const auto reply = client_->call(hand(1), msg::READ_REGISTER, 0, 0x0602);
    ASSERT_TRUE(reply) << "the service stopped answering after a forged sample";
    EXPECT_EQ(reply->code(), msg::OK) << reply->message();
  }
  EXPECT_TRUE(service_alive());
  // Nothing of the forged samples reached the bus: the only write is the last valid one.
  ASSERT_EQ(client_->call(hand(1), msg::SET_CLOSING_FORCE, 55)->code(), msg::OK);
  std::vector<std::string> force_writes;
  for (const auto& frame : frames_as_hex(proxy_->sent())) {
    if (frame.substr(15, 11) == "05 02 01 00") force_writes.push_back(frame);
  }
  EXPECT_THAT(force_writes, ::testing::ElementsAre("FF FE FD FC 01 05 02 01 00 37 00 00 00 FB"));
}

TEST_F(BadInput, RandomRequestsGetOneFittingReplyEachAndNothingForbiddenReachesTheBus) {
  BoxOptions options;
  options.sim_args = {"--object", "1:40", "--speed", "2000"};  // motions end quickly
  ASSERT_NO_FATAL_FAILURE(start(options));
  const std::uint32_t seed = env_number("DH3_RANDOM_SEED", std::random_device{}());
  const std::uint32_t count = env_number("DH3_RANDOM_REQUESTS", 2000);
  std::printf("random requests: seed %u, %u requests (DH3_RANDOM_SEED=%u replays)\n", seed, count,
              seed);
  std::fflush(stdout);
  SCOPED_TRACE("DH3_RANDOM_SEED=" + std::to_string(seed));
  RequestGenerator generator(seed, service_->name(), client_->client_id());

  // Sent in batches well inside the request writer's history (KEEP_LAST 64),
  // each batch answered before the next, so no request is lost on the way.
  std::map<msg::ResultCode, int> codes;
  std::vector<std::pair<std::string, std::uint64_t>> unaddressed;
  std::uint64_t seq = 1000;
  for (std::uint32_t sent = 0; sent < count;) {
    std::vector<msg::CommandRequest> batch;
    for (int i = 0; i < 32 && sent < count; ++i, ++sent) {
      auto request = generator.next();
      request.request_seq(++seq);
      client_->send(request, /*keep_seq=*/true);
      batch.push_back(std::move(request));
    }
    for (const auto& request : batch) {
      const auto& address = request.hand();
      if (!address.service().empty() && address.service() != service_->name()) {
        unaddressed.emplace_back(request.client_id(), request.request_seq());
        continue;
      }
      const auto reply =
          client_->wait_reply(request.request_seq(), std::chrono::seconds(30), request.client_id());
      ASSERT_TRUE(reply) << "no reply to request " << request.request_seq() << " (command "
                         << request.command() << ")";
      ++codes[reply->code()];
      EXPECT_EQ(reply->command(), request.command());
      EXPECT_LE(static_cast<std::uint32_t>(reply->code()), static_cast<std::uint32_t>(msg::FAILED));
      EXPECT_FALSE(reply->code() != msg::OK && reply->message().empty())
          << "code " << reply->code() << " without a message";
      if (const auto expected = decided_code(request)) {
        EXPECT_EQ(reply->code(), *expected)
            << "request " << request.request_seq() << ", command " << request.command()
            << ", value " << request.value() << ", bus '" << address.bus() << "', id "
            << address.can_id() << ": " << reply->message();
      } else {
        EXPECT_THAT(reply->code(),
                    ::testing::Not(AnyOf(Eq(msg::INVALID_ARGUMENT), Eq(msg::UNKNOWN_HAND))))
            << "request " << request.request_seq() << ", command " << request.command()
            << ", value " << request.value() << ": " << reply->message();
      }
    }
    if (HasFatalFailure()) return;
  }
  std::printf("reply codes:");
  for (const auto& [code, n] : codes) std::printf(" %d:%d", static_cast<int>(code), n);
  std::printf("\n");

  const auto duplicate = client_->wait_duplicate_reply(kDuplicateGrace);
  EXPECT_FALSE(duplicate) << client_->describe_replies(duplicate->second, duplicate->first);
  for (const auto& [who, request_seq] : unaddressed) {
    EXPECT_EQ(client_->reply_count(request_seq, who), 0U) << "another service's request answered";
  }
  EXPECT_TRUE(service_alive());
  const auto version = client_->call(hand(2), msg::READ_REGISTER, 0, 0x1301);
  ASSERT_TRUE(version);
  EXPECT_EQ(version->code(), msg::OK);
  EXPECT_THAT(spec_violations(proxy_->sent()), ::testing::IsEmpty());
}

TEST_F(BadInput, AdministrativeCommandsAreDeniedAndNeverReachTheBus) {
  ASSERT_NO_FATAL_FAILURE(start());
  std::vector<std::uint64_t> seqs;
  for (std::uint16_t id = 1; id <= 3; ++id) {
    seqs.push_back(client_->send(client_->request(hand(id), msg::SET_CAN_ID, 9)));
    seqs.push_back(client_->send(client_->request(hand(id), msg::SET_BAUD_RATE, 2)));
  }
  seqs.push_back(client_->send(client_->request(hand(0), msg::SET_CAN_ID, 9)));
  for (const auto& reply : expect_one_reply_each(*client_, seqs)) {
    EXPECT_EQ(reply.code(), msg::DENIED) << reply.message();
    EXPECT_THAT(reply.message(), ::testing::HasSubstr("administrative"));
  }
  // A round trip through every hand's queue: anything sent for the refused
  // commands would be on the wire before it.
  for (std::uint16_t id = 1; id <= 3; ++id) {
    ASSERT_EQ(client_->call(hand(id), msg::SET_CLOSING_FORCE, 50)->code(), msg::OK);
  }
  for (const auto& frame : frames_as_hex(proxy_->sent())) {
    EXPECT_FALSE(frame.substr(15, 11) == "12 01 01 00" || frame.substr(15, 11) == "14 01 01 00")
        << "administrative write on the bus: " << frame;
  }
  EXPECT_THAT(spec_violations(proxy_->sent()), ::testing::IsEmpty());
}

TEST_F(BadInput, FloodsBeyondTheQueueBoundAreAnsweredBusyWithoutMemoryGrowth) {
  // Hand 3 answers each request 20 ms late, so its queue (16) fills.
  ASSERT_NO_FATAL_FAILURE(start());
  ASSERT_THAT(sim_->control("delay 3 20"), StartsWith("ok"));
  auto second = connected_client(service_->name(), "dh3-test-flood");
  ASSERT_TRUE(second);
  const auto flood = [&] {
    // Two writers, 60 requests each, at once: well beyond 16, inside each
    // writer's history (KEEP_LAST 64) so every request reaches the service.
    std::vector<std::uint64_t> mine;
    std::vector<std::uint64_t> theirs;
    for (int i = 0; i < 60; ++i) {
      mine.push_back(client_->send(client_->request(hand(3), msg::READ_REGISTER, 0, 0x0602)));
      theirs.push_back(second->send(second->request(hand(3), msg::READ_REGISTER, 0, 0x0602)));
    }
    int busy = 0;
    int ok = 0;
    const std::pair<DdsTestClient*, const std::vector<std::uint64_t>*> writers[] = {
        {client_.get(), &mine}, {second.get(), &theirs}};
    for (const auto& [client, seqs] : writers) {
      for (const auto seq : *seqs) {
        const auto reply = client->wait_reply(seq, std::chrono::seconds(30));
        EXPECT_TRUE(reply) << "no reply to request " << seq;
        if (!reply) return std::pair{ok, busy};
        EXPECT_THAT(reply->code(), AnyOf(Eq(msg::OK), Eq(msg::BUSY))) << reply->message();
        busy += reply->code() == msg::BUSY;
        ok += reply->code() == msg::OK;
      }
    }
    return std::pair{ok, busy};
  };

  for (int warm_up = 0; warm_up < 3; ++warm_up) flood();
  const long before = resident_kib(service_->process().pid());
  int total_busy = 0;
  for (int round = 0; round < 15; ++round) {
    const auto [ok, busy] = flood();
    EXPECT_GE(busy, 1) << "a flood of 120 requests never hit the queue bound";
    EXPECT_GE(ok, 1) << "nothing of a flood was served";
    total_busy += busy;
    if (HasFailure()) return;
  }
  const long after = resident_kib(service_->process().pid());
  std::printf("floods: 15 x 120 requests, %d BUSY; service VmRSS %ld KiB -> %ld KiB\n", total_busy,
              before, after);
  ASSERT_GT(before, 0);
  // Generous: allocator noise, not a leak of 1800 requests.
  EXPECT_LT(after - before, 8 * 1024) << "VmRSS grew from " << before << " to " << after << " KiB";
  EXPECT_FALSE(client_->wait_duplicate_reply(kDuplicateGrace));
  EXPECT_FALSE(second->wait_duplicate_reply(std::chrono::milliseconds(0)));
  EXPECT_TRUE(service_alive());
  ASSERT_THAT(sim_->control("delay 3 0"), StartsWith("ok"));
  EXPECT_EQ(client_->call(hand(3), msg::SET_CLOSING_FORCE, 60)->code(), msg::OK);
}

}  // namespace
}  // namespace dh3::test
