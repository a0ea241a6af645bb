#pragma once
// A GripperCommand action server for every hand dh3-ros2 sees, made when the
// hand's first status arrives. on_status() runs on the client's dispatcher
// thread; the servers live until this object goes.

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "gripper_action_server.hpp"

namespace dh3::ros2 {

class HandActions {
 public:
  /// `pattern` and `ros_namespace`: Ros2Options::action and ros_namespace.
  HandActions(RosParticipant& participant, Client& client, std::string ros_namespace,
              std::string pattern, JointUnits units);

  void on_status(const HandStatus& status);

 private:
  RosParticipant& participant_;
  Client& client_;
  std::string ros_namespace_;
  std::string pattern_;
  JointUnits units_;
  std::mutex mutex_;
  std::map<HandAddress, std::unique_ptr<GripperActionServer>> servers_;
};

}  // namespace dh3::ros2
