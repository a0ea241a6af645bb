#pragma once
// Everything dh3-ros2 serves for each hand it sees, made when the hand's first
// status arrives: the GripperCommand and ParallelGripperCommand actions and
// the initialize and set_forces services, sharing the hand's HandTurn.
// on_status() runs on the client's dispatcher thread; what it made lives
// until this object goes.

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "gripper_action_server.hpp"
#include "hand_services.hpp"
#include "ros2_options.hpp"

namespace dh3::ros2 {

class HandActions {
 public:
  /// `made` is called after a hand's endpoints were made (for
  /// ros_discovery_info), on the thread of on_status().
  HandActions(RosParticipant& participant, Client& client, const Ros2Options& options,
              std::function<void()> made = {});

  void on_status(const HandStatus& status);

 private:
  struct Face {
    std::unique_ptr<GripperActionServer> gripper;
    std::unique_ptr<GripperActionServer> parallel;
    std::unique_ptr<HandServices> services;
  };
  /// The hand's name for `pattern`, fully qualified; logs why not.
  std::optional<std::string> name_of(const std::string& pattern, const HandAddress& hand) const;
  Face make_face(const HandAddress& hand);

  RosParticipant& participant_;
  Client& client_;
  const Ros2Options& options_;
  std::function<void()> made_;
  std::mutex mutex_;
  std::map<HandAddress, Face> faces_;
};

}  // namespace dh3::ros2
