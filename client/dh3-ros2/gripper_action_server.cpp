#include "gripper_action_server.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "dh3/contract/dh3.h"
#include "dh3/motion_end.hpp"

namespace dh3::ros2 {

namespace {

// action_msgs/msg/GoalStatus and action_msgs/srv/CancelGoal.
constexpr std::int8_t kAccepted = 1;
constexpr std::int8_t kExecuting = 2;
constexpr std::int8_t kCanceling = 3;
constexpr std::int8_t kSucceeded = 4;
constexpr std::int8_t kCanceled = 5;
constexpr std::int8_t kAborted = 6;
constexpr std::int8_t kErrorNone = 0;
constexpr std::int8_t kErrorUnknownGoal = 2;
constexpr std::int8_t kErrorGoalTerminated = 3;

// The contract's least force (docs/protocol-notes.md reading 4).
constexpr std::int32_t kMinForcePercent = dh3::limits::FORCE_MIN;
constexpr auto kLeaseTtl = std::chrono::seconds(30);
constexpr auto kFeedbackPeriod = std::chrono::milliseconds(50);
constexpr auto kMotionDeadline = std::chrono::seconds(30);
constexpr std::size_t kTerminalGoalsKept = 16;

bool terminal(std::int8_t status) {
  return status >= kSucceeded;
}

builtin_interfaces::msg::dds_::Time_ now() {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count();
  builtin_interfaces::msg::dds_::Time_ time;
  time.sec(static_cast<std::int32_t>(ns / 1'000'000'000));
  time.nanosec(static_cast<std::uint32_t>(ns % 1'000'000'000));
  return time;
}

}  // namespace

GripperActionServer::GripperActionServer(RosParticipant& participant, Client& client,
                                         HandAddress hand, const std::string& action,
                                         JointUnits units, std::shared_ptr<HandTurn> turn,
                                         const MakeEndpoints& make_endpoints)
    : client_(client),
      hand_(std::move(hand)),
      action_(action),
      units_(units),
      turn_(std::move(turn)),
      status_(participant.writer("rt" + action + "/_action/status",
                                 eprosima::fastdds::dds::TypeSupport(
                                     new action_msgs::msg::dds_::GoalStatusArray_PubSubType()),
                                 RosQos::action_status)),
      cancel_goal_(
          participant, action + "/_action/cancel_goal",
          [this](const auto& request, const RequestId& id) { on_cancel_goal(request, id); }) {
  // A request may arrive as soon as the endpoints exist, before endpoints_
  // is set: its handler waits for this lock.
  std::lock_guard making(endpoints_made_);
  ActionEndpoints::Handlers handlers;
  handlers.send_goal = [this](const Uuid& goal_id, const Result<GripperGoal, std::string>& command,
                              const RequestId& id) {
    { std::lock_guard made(endpoints_made_); }
    on_send_goal(goal_id, command, id);
  };
  handlers.get_result = [this](const Uuid& goal_id, const RequestId& id) {
    { std::lock_guard made(endpoints_made_); }
    on_get_result(goal_id, id);
  };
  endpoints_ = make_endpoints(std::move(handlers));
}

GripperActionServer::~GripperActionServer() {
  std::vector<std::thread> workers;
  {
    std::lock_guard lock(mutex_);
    for (auto& [id, goal] : goals_) *goal->cancel = true;
    workers.swap(workers_);
  }
  for (auto& worker : workers) worker.join();
}

bool GripperActionServer::ok() const {
  return status_ != nullptr && cancel_goal_.ok() && endpoints_ != nullptr && endpoints_->ok();
}

Result<GripperActionServer::Target, std::string> GripperActionServer::target_of(
    const GripperGoal& command) {
  const auto status = client_.status(hand_);
  if (!status) return fail("no such hand");
  if (!status->online) return fail(std::string("the hand is offline"));
  if (!status->initialized) return fail(std::string("the hand is not initialized"));
  Target target;
  const auto position = units_.opening_percent(command.position);
  if (!position) return fail("position " + std::to_string(command.position) + " out of range");
  target.position = *position;
  if (command.max_effort > 0.0 || std::isnan(command.max_effort)) {
    const auto force = units_.force_percent(command.max_effort);
    if (!force || *force < kMinForcePercent) {
      return fail("max_effort " + std::to_string(command.max_effort) + " out of range");
    }
    target.force = force;
  }
  return target;
}

void GripperActionServer::on_send_goal(const Uuid& goal_id,
                                       const Result<GripperGoal, std::string>& command,
                                       const RequestId& id) {
  const auto stamp = now();
  Result<Target, std::string> target =
      command ? target_of(*command) : Result<Target, std::string>(fail(command.error()));
  if (!target) {
    spdlog::info("dh3-ros2: {} rejects a goal: {}", action_, target.error());
    endpoints_->reply_goal(id, false, stamp);
    return;
  }
  auto goal = std::make_shared<Goal>();
  goal->id = goal_id;
  goal->stamp = stamp;
  goal->status = kAccepted;
  bool accepted = false;
  {
    std::lock_guard lock(mutex_);
    accepted = goals_.count(goal->id) == 0;  // a goal id is used once
    if (accepted) {
      goals_[goal->id] = goal;
      publish_status_locked();
    }
  }
  endpoints_->reply_goal(id, accepted, stamp);
  if (!accepted) return;
  std::lock_guard lock(mutex_);
  workers_.emplace_back([this, goal, target = *target] { execute(goal, target); });
}

void GripperActionServer::execute(const std::shared_ptr<Goal>& goal, Target target) {
  // One goal at a time holds the hand (and this client's lease on it).
  const auto driving = turn_->take_for_goal(goal->cancel);
  if (*goal->cancel) {  // cancelled while it waited
    finish(goal, kCanceled, state_of(client_.status(hand_)));
    return;
  }
  Hand hand = client_.hand(hand_);
  std::int8_t end = kAborted;
  if (auto lease = hand.acquire_lease(kLeaseTtl); !lease) {
    spdlog::warn("dh3-ros2: {} aborts a goal: lease: {}", action_, lease.message);
  } else {
    end = move(hand, goal, target);
    hand.release_lease();
  }
  finish(goal, end, state_of(hand.status()));
}

std::int8_t GripperActionServer::move(Hand& hand, const std::shared_ptr<Goal>& goal,
                                      Target target) {
  if (target.force) {
    if (auto set = hand.set_force(*target.force); !set) {
      spdlog::warn("dh3-ros2: {} aborts a goal: force: {}", action_, set.message);
      return kAborted;
    }
  }
  {
    std::lock_guard lock(mutex_);
    if (!*goal->cancel) set_status(*goal, kExecuting);  // CANCELING stays
  }
  // A move is answered when the hand took it; the motion's end is an event.
  // Any end of a finger motion, a drop or a fault ends the goal.
  MotionEnd::Rule rule;
  rule.faults_end = true;
  MotionEnd end(rule);
  auto watching = hand.subscribe([&end](const HandEvent& event) { end.offer(event); });
  if (auto started = hand.move_to(target.position); !started) {
    if (*goal->cancel) return kCanceled;
    spdlog::warn("dh3-ros2: {} aborts a goal: {}: {}", action_, to_string(started.code),
                 started.message);
    return kAborted;
  }
  const auto deadline = std::chrono::steady_clock::now() + kMotionDeadline;
  std::optional<HandEvent> ended;
  while (!(ended = end.wait(std::chrono::steady_clock::now() + kFeedbackPeriod))) {
    if (*goal->cancel) {
      hand.stop();
      return kCanceled;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      spdlog::warn("dh3-ros2: {} aborts a goal: the motion did not end", action_);
      return kAborted;
    }
    endpoints_->publish_feedback(goal->id, state_of(hand.status()));
  }
  if (ended->kind != EventKind::arrived && ended->kind != EventKind::grasped &&
      ended->kind != EventKind::missed) {
    spdlog::warn("dh3-ros2: {} aborts a goal: {} {}", action_, to_string(ended->kind),
                 ended->message);
    return kAborted;
  }
  // Where the fingers stopped is read just after the event.
  const auto at = ended->timestamp_ns;
  hand.wait_until(
      [at](const HandStatus& s) { return s.grip != GripState::moving && s.read_at_ns > at; },
      std::chrono::milliseconds(kMotionDeadline));
  return kSucceeded;
}

GripperState GripperActionServer::state_of(const std::optional<HandStatus>& status) const {
  GripperState state;
  if (!status || status->position < 0) return state;
  state.position = units_.opening(status->position);
  state.stalled = status->grip == GripState::grasped;
  state.effort = state.stalled ? units_.force(status->closing_force) : 0.0;
  state.reached_goal = status->grip == GripState::arrived;
  state.read_at_ns = status->read_at_ns;
  return state;
}

void GripperActionServer::finish(const std::shared_ptr<Goal>& goal, std::int8_t status,
                                 GripperState result) {
  std::vector<RequestId> waiting;
  {
    std::lock_guard lock(mutex_);
    goal->result = result;
    set_status(*goal, status);
    waiting.swap(goal->waiting_for_result);
    forget_old_goals_locked();
  }
  for (const auto& id : waiting) endpoints_->reply_result(id, status, result);
}

void GripperActionServer::on_get_result(const Uuid& goal_id, const RequestId& id) {
  std::int8_t status = 0;  // an unknown goal: STATUS_UNKNOWN
  GripperState result;
  {
    std::lock_guard lock(mutex_);
    const auto found = goals_.find(goal_id);
    if (found != goals_.end() && !terminal(found->second->status)) {
      found->second->waiting_for_result.push_back(id);  // answered when it ends
      return;
    }
    if (found != goals_.end()) {
      status = found->second->status;
      result = found->second->result;
    }
  }
  endpoints_->reply_result(id, status, result);
}

void GripperActionServer::on_cancel_goal(const action_msgs::srv::dds_::CancelGoal_Request_& request,
                                         const RequestId& id) {
  action_msgs::srv::dds_::CancelGoal_Response_ response;
  const Uuid& wanted = request.goal_info().goal_id().uuid();
  const bool every = std::all_of(wanted.begin(), wanted.end(), [](auto b) { return b == 0; });
  {
    std::lock_guard lock(mutex_);
    bool known = false;
    for (auto& [goal_id, goal] : goals_) {
      if (!every && goal_id != wanted) continue;
      known = true;
      if (terminal(goal->status)) continue;
      *goal->cancel = true;
      set_status(*goal, kCanceling);
      action_msgs::msg::dds_::GoalInfo_ info;
      info.goal_id().uuid(goal_id);
      info.stamp(goal->stamp);
      response.goals_canceling().push_back(info);
    }
    response.return_code(!response.goals_canceling().empty() ? kErrorNone
                         : known || every                    ? kErrorGoalTerminated
                                                             : kErrorUnknownGoal);
  }
  cancel_goal_.reply(id, response);
}

void GripperActionServer::set_status(Goal& goal, std::int8_t status) {
  goal.status = status;
  publish_status_locked();
}

void GripperActionServer::publish_status_locked() {
  action_msgs::msg::dds_::GoalStatusArray_ array;
  for (const auto& [id, goal] : goals_) {
    action_msgs::msg::dds_::GoalStatus_ status;
    status.goal_info().goal_id().uuid(id);
    status.goal_info().stamp(goal->stamp);
    status.status(goal->status);
    array.status_list().push_back(status);
  }
  status_->write(&array);
}

void GripperActionServer::forget_old_goals_locked() {
  std::vector<std::shared_ptr<Goal>> ended;
  for (const auto& [id, goal] : goals_) {
    if (terminal(goal->status)) ended.push_back(goal);
  }
  if (ended.size() <= kTerminalGoalsKept) return;
  std::sort(ended.begin(), ended.end(), [](const auto& a, const auto& b) {
    return std::make_pair(a->stamp.sec(), a->stamp.nanosec()) <
           std::make_pair(b->stamp.sec(), b->stamp.nanosec());
  });
  for (std::size_t i = 0; i + kTerminalGoalsKept < ended.size(); ++i) goals_.erase(ended[i]->id);
}

}  // namespace dh3::ros2
