#pragma once
// ros_discovery_info: the rmw_dds_common/msg/ParticipantEntitiesInfo a ROS 2
// participant publishes so that its nodes appear in ROS 2's graph
// (`ros2 node list`, `node info`, `action info`): the participant's GID and,
// per node, its namespace, name and the GIDs of its readers and writers. A
// GID is the RTPS GUID (prefix, then entity id) zero-padded to rmw's GID size:
// 24 bytes in Humble, 16 in Jazzy (Gid.msg), so the layout is chosen by the
// distribution. Topic "ros_discovery_info" without "rt/", RELIABLE,
// TRANSIENT_LOCAL, KEEP_LAST 1, as rmw_fastrtps publishes it.

#include <fastdds/rtps/common/Guid.h>

#include <memory>
#include <string>
#include <vector>

#include "dh3/base/result.hpp"
#include "ros2_interfacesPubSubTypes.h"
#include "ros_participant.hpp"

namespace dh3::ros2 {

enum class RosDistro { humble, jazzy };

/// One node's entities in a participant, as ros_discovery_info tells them.
struct DiscoveryEntities {
  eprosima::fastrtps::rtps::GUID_t participant;
  std::string node_namespace = "/";
  std::string node_name;
  std::vector<eprosima::fastrtps::rtps::GUID_t> readers;
  std::vector<eprosima::fastrtps::rtps::GUID_t> writers;
};

/// The message in each layout. Pure.
[[nodiscard]] rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_ jazzy_discovery_info(
    const DiscoveryEntities& entities);
[[nodiscard]] rmw_dds_common_humble::msg::dds_::ParticipantEntitiesInfo_ humble_discovery_info(
    const DiscoveryEntities& entities);
/// The type of each layout, under rmw_dds_common's DDS type name.
[[nodiscard]] eprosima::fastdds::dds::TypeSupport discovery_info_type(RosDistro distro);

class DiscoveryInfoPublisher {
 public:
  /// The writer on `participant`, or why Fast DDS refused it. The node is
  /// `node_name` in `node_namespace` (a fully qualified namespace).
  static Result<std::unique_ptr<DiscoveryInfoPublisher>, std::string> create(
      RosParticipant& participant, RosDistro distro, std::string node_namespace,
      std::string node_name);

  /// Publishes the participant's readers and writers as they are now (its own
  /// writer left out, as rmw's is); false when the write failed.
  bool publish();

 private:
  DiscoveryInfoPublisher(RosParticipant& participant, RosDistro distro,
                         eprosima::fastdds::dds::DataWriter* writer, DiscoveryEntities node);

  RosParticipant& participant_;
  RosDistro distro_;
  eprosima::fastdds::dds::DataWriter* writer_;
  DiscoveryEntities node_;
};

}  // namespace dh3::ros2
