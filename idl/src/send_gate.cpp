#include "dh3/contract/send_gate.hpp"

#include <fastdds/rtps/network/SenderResource.h>
#include <fastdds/rtps/transport/ChainingTransport.h>
#include <fastdds/rtps/transport/ChainingTransportDescriptor.h>
#include <fastdds/rtps/transport/UDPTransportDescriptor.h>

#include <chrono>
#include <fastdds/rtps/common/LocatorList.hpp>
#include <utility>

namespace dh3::contract {

namespace {

namespace rtps = eprosima::fastrtps::rtps;
namespace transport = eprosima::fastdds::rtps;

struct GatedTransportDescriptor : transport::ChainingTransportDescriptor {
  GatedTransportDescriptor(std::shared_ptr<transport::TransportDescriptorInterface> low_level,
                           std::shared_ptr<SendGate> shared_gate)
      : ChainingTransportDescriptor(std::move(low_level)), gate(std::move(shared_gate)) {}

  transport::TransportInterface* create_transport() const override;

  std::shared_ptr<SendGate> gate;
};

/// A transport's sends through a SendGate; what it hears goes straight on.
class GatedTransport : public transport::ChainingTransport {
 public:
  explicit GatedTransport(const GatedTransportDescriptor& descriptor)
      : ChainingTransport(descriptor), configuration_(descriptor) {}

  transport::TransportDescriptorInterface* get_configuration() override { return &configuration_; }

  bool send(rtps::SenderResource* sender, const rtps::octet* buffer, std::uint32_t size,
            rtps::LocatorsIterator* begin, rtps::LocatorsIterator* end,
            const std::chrono::steady_clock::time_point& timeout) override {
    if (!configuration_.gate->pass(sender, buffer, size, begin, end)) return true;
    return sender->send(buffer, size, begin, end, timeout);
  }

  void receive(transport::TransportReceiverInterface* next, const rtps::octet* buffer,
               std::uint32_t size, const rtps::Locator_t& local,
               const rtps::Locator_t& remote) override {
    next->OnDataReceived(buffer, size, local, remote);
  }

 private:
  GatedTransportDescriptor configuration_;
};

transport::TransportInterface* GatedTransportDescriptor::create_transport() const {
  return new GatedTransport(*this);
}

}  // namespace

std::shared_ptr<SendGate> SendGate::put_before_transports(
    eprosima::fastdds::dds::DomainParticipantQos& qos) {
  auto gate = std::make_shared<SendGate>();
  auto& transports = qos.transport();
  if (transports.use_builtin_transports) {
    gate->open();
    return gate;
  }
  for (auto& descriptor : transports.user_transports) {
    // UDP only: Fast DDS keeps peers' shared-memory locators only when a
    // descriptor's type is its shared-memory one, so wrapping that would
    // switch shared memory off.
    if (std::dynamic_pointer_cast<transport::UDPTransportDescriptor>(descriptor) == nullptr)
      continue;
    descriptor = std::make_shared<GatedTransportDescriptor>(descriptor, gate);
  }
  return gate;
}

bool SendGate::pass(rtps::SenderResource* sender, const rtps::octet* buffer, std::uint32_t size,
                    rtps::LocatorsIterator* begin, rtps::LocatorsIterator* end) {
  if (open_.load(std::memory_order_acquire)) return true;
  std::lock_guard lock(mutex_);
  if (open_.load(std::memory_order_relaxed)) return true;
  Datagram datagram{sender, std::vector<rtps::octet>(buffer, buffer + size), {}};
  for (; *begin != *end; ++*begin) datagram.destinations.push_back(**begin);
  held_.push_back(std::move(datagram));
  return false;
}

void SendGate::open() {
  std::lock_guard lock(mutex_);
  if (open_.load(std::memory_order_relaxed)) return;
  for (auto& datagram : held_) {
    rtps::Locators begin(datagram.destinations.cbegin());
    rtps::Locators end(datagram.destinations.cend());
    // As Fast DDS bounds a synchronous send; on loopback it never waits.
    const auto timeout = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
    datagram.sender->send(datagram.bytes.data(), static_cast<std::uint32_t>(datagram.bytes.size()),
                          &begin, &end, timeout);
  }
  held_.clear();
  // After the held ones: a send that finds the gate open goes before none of them.
  open_.store(true, std::memory_order_release);
}

std::size_t SendGate::held() const {
  std::lock_guard lock(mutex_);
  return held_.size();
}

}  // namespace dh3::contract
