#pragma once
// What differs between the gripper actions dh3-ros2 serves
// (control_msgs/action/GripperCommand, ParallelGripperCommand): the types of
// their send_goal and get_result services and of their feedback topic.
// GripperActionServer runs goals on the neutral GripperGoal and GripperState;
// an ActionEndpoints turns them into one action's messages. The handlers run
// on Fast DDS listener threads and must not block; the methods may be called
// from any thread.

#include <array>
#include <cstdint>
#include <functional>
#include <string>

#include "dh3/base/result.hpp"
#include "ros2_interfaces.h"
#include "ros_service_server.hpp"

namespace dh3::ros2 {

using Uuid = std::array<std::uint8_t, 16>;

/// A goal in SI units (or percent, with JointUnits::raw_percent).
struct GripperGoal {
  /// The opening between the fingers.
  double position = 0.0;
  /// The largest closing force; 0 or less: the hand's force as it is.
  double max_effort = 0.0;
};

/// The fingers as a result or feedback reports them.
struct GripperState {
  double position = 0.0;
  double effort = 0.0;
  bool stalled = false;
  bool reached_goal = false;
  /// When the values were read from the hand, ns since the epoch; 0: never.
  std::uint64_t read_at_ns = 0;
};

class ActionEndpoints {
 public:
  struct Handlers {
    /// A goal, or why its message is no goal for this hand (it is rejected).
    std::function<void(const Uuid&, const Result<GripperGoal, std::string>&, const RequestId&)>
        send_goal;
    std::function<void(const Uuid&, const RequestId&)> get_result;
  };

  virtual ~ActionEndpoints() = default;
  [[nodiscard]] virtual bool ok() const = 0;
  virtual void reply_goal(const RequestId& id, bool accepted,
                          const builtin_interfaces::msg::dds_::Time_& stamp) = 0;
  /// `status`: action_msgs/msg/GoalStatus; STATUS_UNKNOWN for an unknown goal.
  virtual void reply_result(const RequestId& id, std::int8_t status, const GripperState& state) = 0;
  virtual void publish_feedback(const Uuid& goal, const GripperState& state) = 0;
};

}  // namespace dh3::ros2
