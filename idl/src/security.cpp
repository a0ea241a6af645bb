#include "dh3/contract/security.hpp"

namespace dh3::contract {

void enable_security(eprosima::fastdds::dds::DomainParticipantQos& qos,
                     const SecurityFiles& files) {
  auto& properties = qos.properties().properties();
  for (auto& [name, value] : security_properties(files)) {
    properties.emplace_back(name, value);
  }
}

}  // namespace dh3::contract
