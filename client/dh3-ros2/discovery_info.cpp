#include "discovery_info.hpp"

#include <algorithm>

namespace dh3::ros2 {

namespace {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::GUID_t;

constexpr const char* kTopic = "ros_discovery_info";

/// rmw_fastrtps's copy_from_fastrtps_guid_to_byte_array, the rest zero.
template <typename Gid>
Gid gid_of(const GUID_t& guid) {
  Gid gid;
  gid.data().fill(0);
  std::copy(std::begin(guid.guidPrefix.value), std::end(guid.guidPrefix.value), gid.data().begin());
  std::copy(std::begin(guid.entityId.value), std::end(guid.entityId.value),
            gid.data().begin() + sizeof(guid.guidPrefix.value));
  return gid;
}

template <typename Info, typename Node, typename Gid>
Info message_of(const DiscoveryEntities& entities) {
  Node node;
  node.node_namespace(entities.node_namespace);
  node.node_name(entities.node_name);
  for (const auto& reader : entities.readers) node.reader_gid_seq().push_back(gid_of<Gid>(reader));
  for (const auto& writer : entities.writers) node.writer_gid_seq().push_back(gid_of<Gid>(writer));
  Info info;
  info.gid(gid_of<Gid>(entities.participant));
  info.node_entities_info_seq({node});
  return info;
}

}  // namespace

rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_ jazzy_discovery_info(
    const DiscoveryEntities& entities) {
  namespace j = rmw_dds_common::msg::dds_;
  return message_of<j::ParticipantEntitiesInfo_, j::NodeEntitiesInfo_, j::Gid_>(entities);
}

rmw_dds_common_humble::msg::dds_::ParticipantEntitiesInfo_ humble_discovery_info(
    const DiscoveryEntities& entities) {
  namespace h = rmw_dds_common_humble::msg::dds_;
  return message_of<h::ParticipantEntitiesInfo_, h::NodeEntitiesInfo_, h::Gid_>(entities);
}

fdds::TypeSupport discovery_info_type(RosDistro distro) {
  if (distro == RosDistro::jazzy) {
    return fdds::TypeSupport(new rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_PubSubType());
  }
  auto* humble = new rmw_dds_common_humble::msg::dds_::ParticipantEntitiesInfo_PubSubType();
  // One DDS type name for both layouts, as ROS 2 has it.
  humble->setName("rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_");
  return fdds::TypeSupport(humble);
}

Result<std::unique_ptr<DiscoveryInfoPublisher>, std::string> DiscoveryInfoPublisher::create(
    RosParticipant& participant, RosDistro distro, std::string node_namespace,
    std::string node_name) {
  auto* writer = participant.writer(kTopic, discovery_info_type(distro), RosQos::action_status);
  if (writer == nullptr) return fail(std::string("Fast DDS refused the ros_discovery_info writer"));
  DiscoveryEntities node;
  node.node_namespace = std::move(node_namespace);
  node.node_name = std::move(node_name);
  return std::unique_ptr<DiscoveryInfoPublisher>(
      new DiscoveryInfoPublisher(participant, distro, writer, std::move(node)));
}

DiscoveryInfoPublisher::DiscoveryInfoPublisher(RosParticipant& participant, RosDistro distro,
                                               fdds::DataWriter* writer, DiscoveryEntities node)
    : participant_(participant), distro_(distro), writer_(writer), node_(std::move(node)) {}

bool DiscoveryInfoPublisher::publish() {
  DiscoveryEntities now = node_;
  now.participant = participant_.guid();
  now.readers = participant_.readers();
  now.writers = participant_.writers();
  std::erase(now.writers, writer_->guid());
  if (distro_ == RosDistro::jazzy) {
    auto message = jazzy_discovery_info(now);
    return writer_->write(&message);
  }
  auto message = humble_discovery_info(now);
  return writer_->write(&message);
}

}  // namespace dh3::ros2
