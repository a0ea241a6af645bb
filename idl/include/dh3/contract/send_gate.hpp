#pragma once

#include <fastdds/rtps/common/Locator.h>
#include <fastdds/rtps/transport/TransportInterface.h>

#include <atomic>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <memory>
#include <mutex>
#include <vector>

namespace dh3::contract {

/// Holds back what a participant sends until it can hear the answers, then
/// sends it unchanged: the same datagrams, none added, none lost.
///
/// Why: Fast DDS 2.9 (and every release up to 3.x) enables a participant by
/// sending its first announcement and only then starting to hear
/// (RTPSParticipantImpl::enable: BuiltinProtocols::enable before
/// ReceiverResource::RegisterReceiver). A service answers a new participant
/// once, within about 0.2 ms; an answer that lands in between is dropped
/// (ReceiverResource::OnDataReceived has no receiver yet), and a participant
/// the service knows is not answered again, so a client that hears services
/// only found the service at its next periodic announcement: 1.5-3 s later in
/// 12 of 40 dh3ctl runs. Sending the first announcement after
/// create_participant() has returned closes that window.
class SendGate {
 public:
  /// Puts every UDP user transport of `qos` behind one closed gate. Shared
  /// memory is not gated (an answer over it can still be lost), and a profile
  /// that keeps Fast DDS's built-in transports is left alone.
  [[nodiscard]] static std::shared_ptr<SendGate> put_before_transports(
      eprosima::fastdds::dds::DomainParticipantQos& qos);

  /// Sends what was held, in order, and lets everything through from now on.
  /// Call once the participant is enabled, and only while it exists.
  void open();

  /// False while closed: the datagram is kept for open().
  bool pass(eprosima::fastrtps::rtps::SenderResource* sender,
            const eprosima::fastrtps::rtps::octet* buffer, std::uint32_t size,
            eprosima::fastrtps::rtps::LocatorsIterator* begin,
            eprosima::fastrtps::rtps::LocatorsIterator* end);

  [[nodiscard]] std::size_t held() const;

 private:
  struct Datagram {
    eprosima::fastrtps::rtps::SenderResource* sender;
    std::vector<eprosima::fastrtps::rtps::octet> bytes;
    std::vector<eprosima::fastrtps::rtps::Locator_t> destinations;
  };

  mutable std::mutex mutex_;
  std::atomic<bool> open_{false};  ///< read without the mutex on every send once open
  std::vector<Datagram> held_;
};

}  // namespace dh3::contract
