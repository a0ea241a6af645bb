#include "gripper_command_endpoints.hpp"

namespace dh3::ros2 {

namespace {

gc::GripperCommand_Result_ result_of(const GripperState& state) {
  gc::GripperCommand_Result_ result;
  result.position(state.position);
  result.effort(state.effort);
  result.stalled(state.stalled);
  result.reached_goal(state.reached_goal);
  return result;
}

}  // namespace

GripperCommandEndpoints::GripperCommandEndpoints(RosParticipant& participant,
                                                 const std::string& action, Handlers handlers)
    : handlers_(std::move(handlers)),
      feedback_(participant.writer(
          "rt" + action + "/_action/feedback",
          eprosima::fastdds::dds::TypeSupport(new gc::GripperCommand_FeedbackMessage_PubSubType()),
          RosQos::standard)),
      send_goal_(participant, action + "/_action/send_goal",
                 [this](const gc::GripperCommand_SendGoal_Request_& request, const RequestId& id) {
                   const auto& command = request.goal().command();
                   handlers_.send_goal(request.goal_id().uuid(),
                                       GripperGoal{command.position(), command.max_effort()}, id);
                 }),
      get_result_(
          participant, action + "/_action/get_result",
          [this](const gc::GripperCommand_GetResult_Request_& request, const RequestId& id) {
            handlers_.get_result(request.goal_id().uuid(), id);
          }) {}

bool GripperCommandEndpoints::ok() const {
  return feedback_ != nullptr && send_goal_.ok() && get_result_.ok();
}

void GripperCommandEndpoints::reply_goal(const RequestId& id, bool accepted,
                                         const builtin_interfaces::msg::dds_::Time_& stamp) {
  gc::GripperCommand_SendGoal_Response_ response;
  response.accepted(accepted);
  response.stamp(stamp);
  send_goal_.reply(id, response);
}

void GripperCommandEndpoints::reply_result(const RequestId& id, std::int8_t status,
                                           const GripperState& state) {
  gc::GripperCommand_GetResult_Response_ response;
  response.status(status);
  response.result(result_of(state));
  get_result_.reply(id, response);
}

void GripperCommandEndpoints::publish_feedback(const Uuid& goal, const GripperState& state) {
  gc::GripperCommand_FeedbackMessage_ feedback;
  feedback.goal_id().uuid(goal);
  const auto result = result_of(state);
  feedback.feedback().position(result.position());
  feedback.feedback().effort(result.effort());
  feedback.feedback().stalled(result.stalled());
  feedback.feedback().reached_goal(result.reached_goal());
  feedback_->write(&feedback);
}

}  // namespace dh3::ros2
