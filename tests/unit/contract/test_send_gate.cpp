// idl/include/dh3/contract/send_gate.hpp: what a participant sends before it
// hears is held, then sent unchanged and in order; once open, nothing is held.

#include <fastdds/rtps/network/SenderResource.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <gtest/gtest.h>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/rtps/common/LocatorList.hpp>
#include <string>
#include <vector>

#include "dh3/contract/participant.hpp"
#include "dh3/contract/send_gate.hpp"
#include "support/test_domain.hpp"

namespace {

namespace rtps = eprosima::fastrtps::rtps;

/// Records every datagram it is asked to send and where to.
class RecordingSender : public rtps::SenderResource {
 public:
  struct Sent {
    std::string bytes;
    std::vector<std::uint32_t> ports;
  };

  RecordingSender() : SenderResource(LOCATOR_KIND_UDPv4) {
    send_lambda_ = [this](const rtps::octet* data, std::uint32_t size,
                          rtps::LocatorsIterator* begin, rtps::LocatorsIterator* end,
                          const std::chrono::steady_clock::time_point&) {
      Sent one{std::string(reinterpret_cast<const char*>(data), size), {}};
      for (; *begin != *end; ++*begin) one.ports.push_back((**begin).port);
      sent.push_back(std::move(one));
      return true;
    };
  }

  std::vector<Sent> sent;
};

/// Offers `bytes` to the gate for `ports`, as a transport does before sending.
bool offer(dh3::contract::SendGate& gate, RecordingSender& sender, const std::string& bytes,
           const std::vector<std::uint32_t>& ports) {
  std::vector<rtps::Locator_t> destinations(ports.size());
  for (std::size_t i = 0; i < ports.size(); ++i) destinations[i].port = ports[i];
  rtps::Locators begin(destinations.cbegin());
  rtps::Locators end(destinations.cend());
  return gate.pass(&sender, reinterpret_cast<const rtps::octet*>(bytes.data()),
                   static_cast<std::uint32_t>(bytes.size()), &begin, &end);
}

TEST(SendGate, HoldsWhileClosedAndSendsInOrderWhenOpened) {
  dh3::contract::SendGate gate;
  RecordingSender sender;
  EXPECT_FALSE(offer(gate, sender, "first", {7400, 7410}));
  EXPECT_FALSE(offer(gate, sender, "second", {7412}));
  EXPECT_TRUE(sender.sent.empty());
  EXPECT_EQ(gate.held(), 2U);

  gate.open();
  ASSERT_EQ(sender.sent.size(), 2U);
  EXPECT_EQ(sender.sent[0].bytes, "first");
  EXPECT_EQ(sender.sent[0].ports, (std::vector<std::uint32_t>{7400, 7410}));
  EXPECT_EQ(sender.sent[1].bytes, "second");
  EXPECT_EQ(sender.sent[1].ports, (std::vector<std::uint32_t>{7412}));
  EXPECT_EQ(gate.held(), 0U);
}

TEST(SendGate, LetsEverythingThroughOnceOpen) {
  dh3::contract::SendGate gate;
  RecordingSender sender;
  gate.open();
  EXPECT_TRUE(offer(gate, sender, "later", {7400}));
  EXPECT_EQ(gate.held(), 0U);
  gate.open();                       // a second open sends nothing again
  EXPECT_TRUE(sender.sent.empty());  // the transport sends what passes, not the gate
}

TEST(SendGate, LeavesFastDdsBuiltinTransportsAlone) {
  eprosima::fastdds::dds::DomainParticipantQos qos;  // built-in transports
  const auto gate = dh3::contract::SendGate::put_before_transports(qos);
  EXPECT_TRUE(qos.transport().user_transports.empty());
  RecordingSender sender;
  EXPECT_TRUE(offer(*gate, sender, "x", {7400}));
}

TEST(SendGate, GatesUdpAndLeavesSharedMemoryAsFastDdsKnowsIt) {
  auto qos = dh3::contract::participant_qos("send-gate", {.interfaces = {}, .shared_memory = true});
  ASSERT_EQ(qos.transport().user_transports.size(), 2U);
  const auto gate = dh3::contract::SendGate::put_before_transports(qos);
  const auto& transports = qos.transport().user_transports;
  EXPECT_EQ(
      std::dynamic_pointer_cast<eprosima::fastdds::rtps::UDPv4TransportDescriptor>(transports[0]),
      nullptr);
  EXPECT_NE(std::dynamic_pointer_cast<eprosima::fastdds::rtps::SharedMemTransportDescriptor>(
                transports[1]),
            nullptr);
}

// What the gate is for: Fast DDS sends a participant's first announcement
// inside create_participant(), before the participant hears anything.
TEST(SendGate, HoldsTheFirstAnnouncementMadeWhileTheParticipantIsCreated) {
  namespace fdds = eprosima::fastdds::dds;
  auto qos = dh3::contract::participant_qos("send-gate", {});
  const auto gate = dh3::contract::SendGate::put_before_transports(qos);
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  auto* participant =
      factory->create_participant(static_cast<fdds::DomainId_t>(dh3::test::test_domain()), qos);
  ASSERT_NE(participant, nullptr);
  EXPECT_GE(gate->held(), 1U);
  gate->open();
  EXPECT_EQ(gate->held(), 0U);
  EXPECT_EQ(factory->delete_participant(participant),
            eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK);
}

}  // namespace
