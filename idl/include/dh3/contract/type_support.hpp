#pragma once
// The type support every dh3 participant registers for the contract's topics:
// fastddsgen's, made total. The generated deserialize() lets Fast CDR's
// BadParamException escape (a sample whose encapsulation it does not know,
// e.g. another vendor's XCDR2, or any forged payload), and Fast DDS does not
// catch it on the reader's thread: one such sample would end the process.
// Here such a sample is refused, and the half-read sample is reset so nothing
// of an earlier one shows through (the service then answers it as malformed).
// create_topics() registers it for every topic of the contract.

#include <fastcdr/exceptions/Exception.h>
#include <fastdds/rtps/common/SerializedPayload.h>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/topic/Topic.hpp>

#include "dh3/contract/dh3.h"
#include "dh3/contract/dh3PubSubTypes.h"

namespace dh3::contract {

/// `Generated`: a fastddsgen PubSubType, e.g. msg::CommandRequestPubSubType.
template <typename Generated>
class TypeSupport final : public Generated {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    try {
      if (Generated::deserialize(payload, data)) return true;
    } catch (const eprosima::fastcdr::exception::Exception&) {
    }
    *static_cast<typename Generated::type*>(data) = typename Generated::type{};
    return false;
  }
};

/// The contract's nine topics on one participant, each with its type
/// registered through TypeSupport. A member is nullptr where Fast DDS refused.
/// The lease topic (a service's and its standby's) is not needed for
/// complete(): a participant whose permissions predate it works without it.
struct Topics {
  eprosima::fastdds::dds::Topic* status = nullptr;
  eprosima::fastdds::dds::Topic* event = nullptr;
  eprosima::fastdds::dds::Topic* info = nullptr;
  eprosima::fastdds::dds::Topic* request = nullptr;
  eprosima::fastdds::dds::Topic* reply = nullptr;
  eprosima::fastdds::dds::Topic* group_request = nullptr;
  eprosima::fastdds::dds::Topic* group_reply = nullptr;
  eprosima::fastdds::dds::Topic* owner = nullptr;
  eprosima::fastdds::dds::Topic* lease = nullptr;
  eprosima::fastdds::dds::Topic* admin_request = nullptr;

  [[nodiscard]] bool complete() const;
};

Topics create_topics(eprosima::fastdds::dds::DomainParticipant& participant);

}  // namespace dh3::contract
