#include "parallel_gripper_endpoints.hpp"

namespace dh3::ros2 {

namespace {

constexpr std::uint64_t kNanosPerSecond = 1'000'000'000;

}  // namespace

ParallelGripperEndpoints::ParallelGripperEndpoints(RosParticipant& participant,
                                                   const std::string& action,
                                                   std::string finger_joint, Handlers handlers)
    : finger_joint_(std::move(finger_joint)),
      handlers_(std::move(handlers)),
      feedback_(
          participant.writer("rt" + action + "/_action/feedback",
                             eprosima::fastdds::dds::TypeSupport(
                                 new pgc::ParallelGripperCommand_FeedbackMessage_PubSubType()),
                             RosQos::standard)),
      send_goal_(participant, action + "/_action/send_goal",
                 [this](const pgc::ParallelGripperCommand_SendGoal_Request_& request,
                        const RequestId& id) {
                   handlers_.send_goal(request.goal_id().uuid(),
                                       goal_of(request.goal().command(), finger_joint_), id);
                 }),
      get_result_(
          participant, action + "/_action/get_result",
          [this](const pgc::ParallelGripperCommand_GetResult_Request_& request,
                 const RequestId& id) { handlers_.get_result(request.goal_id().uuid(), id); }) {}

Result<GripperGoal, std::string> ParallelGripperEndpoints::goal_of(
    const sensor_msgs::msg::dds_::JointState_& command, const std::string& finger_joint) {
  if (command.position().size() != 1) {
    return fail("command.position holds " + std::to_string(command.position().size()) +
                " values, not the finger joint's one");
  }
  if (!command.name().empty() &&
      (command.name().size() != 1 || command.name()[0] != finger_joint)) {
    return fail("command.name is not [" + finger_joint + "]");
  }
  if (command.effort().size() > 1) return fail(std::string("command.effort holds more than one"));
  GripperGoal goal;
  goal.position = command.position()[0];
  if (!command.effort().empty()) goal.max_effort = command.effort()[0];
  return goal;
}

sensor_msgs::msg::dds_::JointState_ ParallelGripperEndpoints::joint_state_of(
    const GripperState& state) const {
  sensor_msgs::msg::dds_::JointState_ joint;
  joint.header().stamp().sec(static_cast<std::int32_t>(state.read_at_ns / kNanosPerSecond));
  joint.header().stamp().nanosec(static_cast<std::uint32_t>(state.read_at_ns % kNanosPerSecond));
  joint.name({finger_joint_});
  joint.position({state.position});
  joint.effort({state.effort});
  return joint;
}

bool ParallelGripperEndpoints::ok() const {
  return feedback_ != nullptr && send_goal_.ok() && get_result_.ok();
}

void ParallelGripperEndpoints::reply_goal(const RequestId& id, bool accepted,
                                          const builtin_interfaces::msg::dds_::Time_& stamp) {
  pgc::ParallelGripperCommand_SendGoal_Response_ response;
  response.accepted(accepted);
  response.stamp(stamp);
  send_goal_.reply(id, response);
}

void ParallelGripperEndpoints::reply_result(const RequestId& id, std::int8_t status,
                                            const GripperState& state) {
  pgc::ParallelGripperCommand_GetResult_Response_ response;
  response.status(status);
  response.result().state(joint_state_of(state));
  response.result().stalled(state.stalled);
  response.result().reached_goal(state.reached_goal);
  get_result_.reply(id, response);
}

void ParallelGripperEndpoints::publish_feedback(const Uuid& goal, const GripperState& state) {
  pgc::ParallelGripperCommand_FeedbackMessage_ feedback;
  feedback.goal_id().uuid(goal);
  feedback.feedback().state(joint_state_of(state));
  feedback_->write(&feedback);
}

}  // namespace dh3::ros2
