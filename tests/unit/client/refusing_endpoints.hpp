#pragma once
// An EndpointCreator that refuses some of the client's endpoints the way DDS
// Security's access control does (their creation fails), so a test can take
// the read-only path without credentials.

#include <set>
#include <utility>

#include "client_endpoints.hpp"

namespace dh3::test {

class RefusingEndpoints final : public detail::EndpointCreator {
 public:
  explicit RefusingEndpoints(std::set<detail::ClientEndpoint> refused)
      : refused_(std::move(refused)) {}

  /// A refusal here stands for access control's.
  [[nodiscard]] bool access_control(const contract::Participant& /*participant*/) const override {
    return true;
  }
  [[nodiscard]] detail::fdds::DataWriter* create_writer(
      detail::ClientEndpoint which, detail::fdds::Publisher& publisher, detail::fdds::Topic* topic,
      const detail::fdds::DataWriterQos& qos, detail::fdds::DataWriterListener* listener,
      const detail::fdds::StatusMask& mask) const override {
    if (refused_.count(which) > 0) return nullptr;
    return EndpointCreator::create_writer(which, publisher, topic, qos, listener, mask);
  }
  [[nodiscard]] detail::fdds::DataReader* create_reader(
      detail::ClientEndpoint which, detail::fdds::Subscriber& subscriber,
      detail::fdds::TopicDescription* topic, const detail::fdds::DataReaderQos& qos,
      detail::fdds::DataReaderListener* listener,
      const detail::fdds::StatusMask& mask) const override {
    if (refused_.count(which) > 0) return nullptr;
    return EndpointCreator::create_reader(which, subscriber, topic, qos, listener, mask);
  }

 private:
  std::set<detail::ClientEndpoint> refused_;
};

}  // namespace dh3::test
