#include "dh3/contract/type_support.hpp"

#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <string>

namespace dh3::contract {

bool Topics::complete() const {
  return status != nullptr && event != nullptr && info != nullptr && request != nullptr &&
         reply != nullptr && group_request != nullptr && group_reply != nullptr &&
         owner != nullptr && admin_request != nullptr;
}

Topics create_topics(eprosima::fastdds::dds::DomainParticipant& participant) {
  namespace fdds = eprosima::fastdds::dds;
  const auto topic = [&participant](const std::string& name, fdds::TopicDataType* type) {
    fdds::TypeSupport support(type);
    support.register_type(&participant);
    return participant.create_topic(name, support.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  };
  Topics topics;
  topics.status = topic(dh3::topics::HAND_STATUS, new TypeSupport<msg::HandStatusPubSubType>());
  topics.event = topic(dh3::topics::HAND_EVENT, new TypeSupport<msg::HandEventPubSubType>());
  topics.info = topic(dh3::topics::SERVICE_INFO, new TypeSupport<msg::ServiceInfoPubSubType>());
  topics.request =
      topic(dh3::topics::COMMAND_REQUEST, new TypeSupport<msg::CommandRequestPubSubType>());
  topics.reply = topic(dh3::topics::COMMAND_REPLY, new TypeSupport<msg::CommandReplyPubSubType>());
  topics.group_request =
      topic(dh3::topics::GROUP_REQUEST, new TypeSupport<msg::GroupRequestPubSubType>());
  topics.group_reply =
      topic(dh3::topics::GROUP_REPLY, new TypeSupport<msg::GroupReplyPubSubType>());
  topics.owner =
      topic(dh3::topics::SERVICE_OWNER, new TypeSupport<msg::ServiceOwnerPubSubType>());
  topics.lease = topic(dh3::topics::HAND_LEASE, new TypeSupport<msg::HandLeasePubSubType>());
  topics.admin_request =
      topic(dh3::topics::ADMIN_REQUEST, new TypeSupport<msg::CommandRequestPubSubType>());
  return topics;
}

}  // namespace dh3::contract
