#pragma once
// Publishes every hand's status that reaches dh3-ros2 as a
// sensor_msgs/JointState on the joint_states topic (one message per status,
// holding that hand's two joints, as a joint_state_broadcaster per hand would).
// on_status() may be called from any thread.

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <string>

#include "dh3/base/result.hpp"
#include "joint_state_message.hpp"
#include "ros_participant.hpp"

namespace dh3::ros2 {

class JointStatePublisher {
 public:
  /// `topic` is the DDS topic ("rt/joint_states").
  static Result<JointStatePublisher, std::string> create(RosParticipant& participant,
                                                         const std::string& topic,
                                                         JointNames names, JointUnits units);

  /// Writes the hand's joint state; false when Fast DDS refused the sample.
  bool on_status(const HandStatus& status);

 private:
  JointStatePublisher(eprosima::fastdds::dds::DataWriter* writer, JointNames names,
                      JointUnits units);
  eprosima::fastdds::dds::DataWriter* writer_;
  JointNames names_;
  JointUnits units_;
};

}  // namespace dh3::ros2
