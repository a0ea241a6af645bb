#include "joint_state_publisher.hpp"

#include <utility>

#include "ros2_interfacesPubSubTypes.h"

namespace dh3::ros2 {

Result<JointStatePublisher, std::string> JointStatePublisher::create(RosParticipant& participant,
                                                                     const std::string& topic,
                                                                     JointNames names,
                                                                     JointUnits units) {
  auto* writer = participant.writer(
      topic,
      eprosima::fastdds::dds::TypeSupport(new sensor_msgs::msg::dds_::JointState_PubSubType()),
      RosQos::standard);
  if (writer == nullptr) return fail("Fast DDS could not create the writer of " + topic);
  return JointStatePublisher(writer, std::move(names), std::move(units));
}

JointStatePublisher::JointStatePublisher(eprosima::fastdds::dds::DataWriter* writer,
                                         JointNames names, JointUnits units)
    : writer_(writer), names_(std::move(names)), units_(std::move(units)) {}

bool JointStatePublisher::on_status(const HandStatus& status) {
  auto message = joint_state_of(status, names_, units_);
  return writer_->write(&message);
}

}  // namespace dh3::ros2
