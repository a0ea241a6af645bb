// HandDriver: commands in, which frame goes out next (a re-send, a command's
// step, a probe, a confirming read, a poll) and the motions that sending
// starts, the hand's lifecycle (online, offline, link loss, shutdown), time
// (timeouts, deadlines, wake-ups) and reporting. What comes back is
// hand_driver_receiving.cpp.

#include "hand_driver.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <utility>

#include "dh3/hand/command_validation.hpp"
#include "dh3/hand/group_release.hpp"

namespace dh3::hand {
namespace {

namespace reg = protocol::reg;
using protocol::Message;
using protocol::Register;

/// Read afresh whenever a hand comes online.
constexpr Register kRefresh[] = {reg::kInitialize,    reg::kClosingForce, reg::kOpeningForce,
                                 reg::kPosition,      reg::kGripStatus,   reg::kRotation,
                                 reg::kRotationStatus};

std::string hand_label(const std::string& bus, std::uint8_t can_id, const std::string& name) {
  return name.empty() ? fmt::format("{}/{}", bus, can_id)
                      : fmt::format("{}/{} ({})", bus, can_id, name);
}

}  // namespace

HandDriver::HandDriver(HandConfig config, DriverContext& context, std::atomic<int>& queued,
                       HandCounters& counters, TimePoint now, bool anonymous)
    : context_(context),
      options_(context.options),
      counters_(counters),
      anonymous_(anonymous),
      outbox_(context.observer, context.roster, context.latency, context.options.poll_interval_idle,
              anonymous),
      link_(Offline{now}),
      ledger_(queued, counters, outbox_, hand_label(context.bus_name, config.can_id, config.name)),
      slot_(context.options.frame_spacing(), context.options.max_retries, now) {
  state_.can_id = config.can_id;
  state_.name = std::move(config.name);
  state_.updated_at = now;
}

void HandDriver::warm(const HandState& seen) {
  state_.initialized = seen.initialized;
  state_.grip = seen.grip;
  state_.position = seen.position;
  state_.target_position = seen.target_position;
  state_.closing_force = seen.closing_force;
  state_.opening_force = seen.opening_force;
  state_.rotation = seen.rotation;
  state_.rotation_target = seen.rotation_target;
  state_.rotation_state = seen.rotation_state;
  state_.read_at = seen.read_at;
}

std::string HandDriver::label() const {
  return hand_label(context_.bus_name, state_.can_id, state_.name);
}

// ---------------------------------------------------------------------------
// Commands in

void HandDriver::enqueue(Job job, TimePoint now) {
  ledger_.add(std::move(job));
  flush(now);
}

Duration HandDriver::reply_timeout_for(const Job& job) const {
  const Command& command = job.command;
  if (command.kind == CommandKind::write_register && is_admin_register(command.reg)) {
    return options_.admin_reply_timeout;
  }
  return options_.reply_timeout;
}

// ---------------------------------------------------------------------------
// Frames out: a re-send, the active command's step, else a probe, a confirming
// read or a poll

std::optional<Message> HandDriver::next_frame(TimePoint now) {
  if (!slot_.clear_to_send(now)) return std::nullopt;
  if (auto again = slot_.send_again(now)) return again;
  if (auto frame = job_frame(now)) {
    flush(now);
    return frame;
  }
  if (holding_for_group()) {
    flush(now);
    return std::nullopt;
  }
  auto frame = anonymous_ ? std::nullopt : background_frame(now);
  flush(now);
  return frame;
}

std::optional<Message> HandDriver::next_group_frame(TimePoint now) {
  if (!holding_for_group() || slot_.has_resend() || !slot_.clear_to_send(now)) return std::nullopt;
  releasing_group_ = true;
  auto frame = job_frame(now);
  releasing_group_ = false;
  flush(now);
  return frame;
}

bool HandDriver::has_command_frame() const {
  return !slot_.in_flight() && (slot_.has_resend() || ledger_.has_commands());
}

// ---------------------------------------------------------------------------
// Commands out: the active command's frames, one step at a time

void HandDriver::start_next_job(TimePoint now) {
  while (!active()) {
    std::optional<Job> job = ledger_.take_next(now);
    if (!job) return;
    const CommandKind kind = job->command.kind;
    ActiveJob next{std::move(*job), first_step(kind)};
    if (needs_initialization(next.job.command)) {
      if (!init_known()) {
        next.check_initialized_first = true;
      } else if (!state_.initialized) {
        if (kind == CommandKind::stop) {
          // Nothing moves before initialization: there is nothing to stop.
          ledger_.complete(next.job, CommandSuccess{state_.position, GraspOutcome::none});
        } else {
          set_error(CommandError::not_initialized,
                    fmt::format("{} before initialization", to_string(kind)));
          ledger_.complete(next.job, fail(CommandError::not_initialized));
        }
        continue;
      }
    }
    ledger_.start(std::move(next));
  }
}

bool HandDriver::at_group_gate() const {
  if (!active() || !active()->job.command.group || active()->group_released ||
      active()->check_initialized_first) {
    return false;
  }
  // The frame that starts the motion (or sets the force): what the group
  // wants to leave together. The steps before it go as they come.
  if (const auto* grasp = std::get_if<GraspStep>(&active()->step))
    return *grasp == GraspStep::close;
  if (const auto* init = std::get_if<InitializeStep>(&active()->step))
    return *init == InitializeStep::start;
  return true;
}

bool HandDriver::pass_group_gate(TimePoint now) {
  GroupRelease& group = *active()->job.command.group;
  if (!active()->group_ready) {
    // next_frame() got here: nothing in flight and the interval clear.
    active()->group_ready = true;
    group.ready(now, context_.wake);
  }
  switch (group.verdict(now)) {
    case GroupRelease::Verdict::hold:
      return false;
    case GroupRelease::Verdict::go:
      // Only in the scheduler's group sweep, so a bus's members go back to back.
      if (!releasing_group_) return false;
      active()->group_released = true;
      return true;
    case GroupRelease::Verdict::abandoned:
      set_error(CommandError::cancelled, "group command abandoned: " + group.abandoned_because());
      ledger_.finish_active(fail(CommandError::cancelled));
      return false;
  }
  return false;
}

bool HandDriver::holding_for_group() const {
  return active() && active()->group_ready && !active()->group_released;
}

Message HandDriver::send_job(Message message, TimePoint now) {
  const bool retryable =
      // CAN ID and baud rate reply only once stored: a re-send would store twice.
      !(message.access == protocol::Access::write && is_admin_register(message.reg));
  if (!std::exchange(active()->frame_sent, true)) {
    context_.latency.command_to_frame.observe(now - active()->job.submitted);
  }
  return slot_.send(message, Purpose::job, now, retryable, reply_timeout_for(active()->job));
}

std::optional<Message> HandDriver::job_frame(TimePoint now) {
  start_next_job(now);
  if (!active()) return std::nullopt;
  const std::uint8_t id = state_.can_id;
  const Command& command = active()->job.command;
  if (active()->check_initialized_first)
    return send_job(protocol::make_read(id, reg::kInitialize), now);
  if (at_group_gate() && !pass_group_gate(now)) return std::nullopt;

  switch (command.kind) {
    case CommandKind::initialize:
      return initialize_frame(now, std::get<InitializeStep>(active()->step));
    case CommandKind::grasp:
      return grasp_frame(now, std::get<GraspStep>(active()->step));
    case CommandKind::stop:
      return stop_frame(now, std::get<StopStep>(active()->step));
    case CommandKind::move_to:
      finger_motion_sent(command.value, command.value == 0);
      return send_job(protocol::make_write(id, reg::kPosition, command.value), now);
    case CommandKind::release:
      finger_motion_sent(command.value, false);
      return send_job(protocol::make_write(id, reg::kPosition, command.value), now);
    case CommandKind::rotate_to:
      rotation_motion_sent(command.value);
      return send_job(protocol::make_write(id, reg::kRotation, command.value), now);
    case CommandKind::set_closing_force:
      return send_job(protocol::make_write(id, reg::kClosingForce, command.value), now);
    case CommandKind::set_opening_force:
      return send_job(protocol::make_write(id, reg::kOpeningForce, command.value), now);
    case CommandKind::read_register:
      return send_job(protocol::make_read(id, command.reg), now);
    case CommandKind::write_register:
      if (command.reg == reg::kPosition) finger_motion_sent(command.value, command.value == 0);
      if (command.reg == reg::kRotation) rotation_motion_sent(command.value);
      return send_job(protocol::make_write(id, command.reg, command.value), now);
  }
  return std::nullopt;
}

std::optional<Message> HandDriver::initialize_frame(TimePoint now, InitializeStep step) {
  // The document's frames: enable the feedback, then initialize (data 0).
  const std::uint8_t id = state_.can_id;
  switch (step) {
    case InitializeStep::enable_feedback:
      return send_job(protocol::make_write(id, reg::kInitFeedback, 0), now);
    case InitializeStep::start:
      return send_job(protocol::make_write(id, reg::kInitialize, 0), now);
  }
  return std::nullopt;
}

std::optional<Message> HandDriver::grasp_frame(TimePoint now, GraspStep step) {
  const std::uint8_t id = state_.can_id;
  switch (step) {
    case GraspStep::set_force:
      return send_job(protocol::make_write(id, reg::kClosingForce, active()->job.command.value),
                      now);
    case GraspStep::close:
      finger_motion_sent(0, true);
      return send_job(protocol::make_write(id, reg::kPosition, 0), now);
  }
  return std::nullopt;
}

std::optional<Message> HandDriver::stop_frame(TimePoint now, StopStep step) {
  // Read where the fingers and the rotation are, and make that their target.
  const std::uint8_t id = state_.can_id;
  switch (step) {
    case StopStep::read_position:
      return send_job(protocol::make_read(id, reg::kPosition), now);
    case StopStep::hold_position:
      // Reached only while the fingers move (advance_stop): a hand at rest is
      // not sent a motion, so it reports no arrival it did not make.
      finger_motion_sent(active()->held, false, fingers_.motion()->reported_target());
      return send_job(protocol::make_write(id, reg::kPosition, active()->held), now);
    case StopStep::read_rotation:
      return send_job(protocol::make_read(id, reg::kRotation), now);
    case StopStep::hold_rotation:
      rotation_motion_sent(active()->held, rotation_.motion()->reported_target());
      return send_job(protocol::make_write(id, reg::kRotation, active()->held), now);
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------
// Probes and reads of the hand's own state

std::optional<Message> HandDriver::background_frame(TimePoint now) {
  if (Online* on = online()) return online_frame(*on, now);
  auto& offline = std::get<Offline>(link_);
  if (now < offline.next_probe_at) return std::nullopt;
  offline.next_probe_at = now + options_.offline_probe_interval;
  return slot_.send(protocol::make_read(state_.can_id, reg::kFirmwareVersion), Purpose::probe, now,
                    false, options_.reply_timeout);
}

std::optional<Message> HandDriver::online_frame(Online& on, TimePoint now) {
  const std::uint8_t id = state_.can_id;
  if (fingers_.take_read_due()) {
    return slot_.send(protocol::make_read(id, reg::kPosition), Purpose::confirm_position, now, true,
                      options_.reply_timeout);
  }
  if (rotation_.take_read_due()) {
    return slot_.send(protocol::make_read(id, reg::kRotation), Purpose::confirm_rotation, now, true,
                      options_.reply_timeout);
  }
  Initializing* init = std::get_if<Initializing>(&on.init);
  if (init && (init->check_now || now >= init->next_check_at)) {
    init->check_now = false;
    init->next_check_at = now + options_.poll_interval_moving;
    return slot_.send(protocol::make_read(id, reg::kInitialize), Purpose::init_check, now, false,
                      options_.reply_timeout);
  }
  if (!on.refresh.empty()) {
    const Register r = on.refresh.front();
    on.refresh.pop_front();
    return slot_.send(protocol::make_read(id, r), Purpose::refresh, now, true,
                      options_.reply_timeout);
  }
  PollSchedule& poll = on.poll;
  const std::optional<std::size_t> next =
      next_poll(poll_plan(), poll.last_read, poll.previous, now);
  if (!next) return std::nullopt;
  poll.last_read[*next] = now;
  poll.previous = next;
  return slot_.send(protocol::make_read(id, kPolledRegisters[*next]), Purpose::poll, now, false,
                    options_.reply_timeout);
}

// ---------------------------------------------------------------------------
// Motions started by sending

void HandDriver::finger_motion_sent(std::int32_t target, bool gripping,
                                    std::optional<std::int32_t> stopped_target) {
  if (active()) active()->motion_sent = true;
  // A grasp or release waiting for the previous motion to end is superseded.
  ledger_.finish_motion_waiter(fail(CommandError::cancelled));
  ++finger_epoch_;
  fingers_.start(FingerMotion{.target = target,
                              .gripping = gripping,
                              .closing = state_.position < 0 || target < state_.position,
                              .stopped_target = stopped_target});
  hold_untouched_ = false;
  state_.target_position = target;
  state_.grip = GripState::moving;
}

void HandDriver::rotation_motion_sent(std::int32_t target,
                                      std::optional<std::int32_t> stopped_target) {
  if (active()) active()->motion_sent = true;
  rotation_.start(RotationMotion{.target = target, .stopped_target = stopped_target});
  state_.rotation_target = target;
  state_.rotation_state = RotationState::moving;
}

// ---------------------------------------------------------------------------
// Lifecycle

Initializing* HandDriver::initializing() {
  Online* on = online();
  return on ? std::get_if<Initializing>(&on->init) : nullptr;
}

const Initializing* HandDriver::initializing() const {
  const Online* on = online();
  return on ? std::get_if<Initializing>(&on->init) : nullptr;
}

bool HandDriver::init_known() const {
  const Online* on = online();
  return on && !std::holds_alternative<InitUnknown>(on->init);
}

void HandDriver::set_init(InitState init) {
  Online* on = online();
  if (!on) return;  // known only while the hand answers
  if (std::holds_alternative<Initialized>(init)) state_.initialized = true;
  if (std::holds_alternative<NotInitialized>(init) || std::holds_alternative<Initializing>(init)) {
    state_.initialized = false;
  }
  on->init = init;
}

PollPlan HandDriver::poll_plan() const {
  // Status 0 also means "default" (after power-on or initialization), so only
  // motions we commanded count as moving.
  PollActivity activity;
  if (const auto& motion = fingers_.motion()) {
    activity.fingers = motion->closing ? FingerActivity::closing : FingerActivity::opening;
  } else if (state_.grip == GripState::grasped) {
    activity.fingers = FingerActivity::holding;
  }
  activity.rotating = rotation_.motion().has_value();
  activity.initializing = initializing() != nullptr;
  return plan_polls(activity,
                    PollIntervals{.watch = options_.poll_interval_watch,
                                  .moving = options_.poll_interval_moving,
                                  .idle = options_.poll_interval_idle,
                                  .during_motion = options_.poll_interval_position_moving});
}

void HandDriver::on_answer(TimePoint now) {
  consecutive_timeouts_ = 0;
  if (state_.read_at == TimePoint{} && state_.last_error == CommandError::timeout) {
    set_error(CommandError::timeout, {});  // "never answered" is over
    state_.last_error.reset();
  }
  state_.read_at = now;
  if (online() || anonymous_) return;
  Online fresh;
  fresh.refresh.assign(std::begin(kRefresh), std::end(kRefresh));
  link_ = std::move(fresh);
  state_.online = true;
  emit(EventKind::online, now, state_.firmware_version);
}

void HandDriver::lose_link(TimePoint now, LinkLoss loss, const std::string& why) {
  slot_.clear();
  fingers_.clear();
  rotation_.clear();
  const bool was_online = online() != nullptr;
  // Probed again after the probe interval; a returning link probes at once.
  link_ = Offline{now + options_.offline_probe_interval};
  state_.online = false;
  switch (loss) {
    case LinkLoss::unanswered:
      set_error(CommandError::timeout, why);
      break;
    case LinkLoss::bus_down:
      set_error(CommandError::bus_down, why);
      break;
    case LinkLoss::shutdown:
      break;
  }
  if (was_online && !anonymous_) {
    emit(EventKind::offline, now, loss == LinkLoss::unanswered ? consecutive_timeouts_ : 0, why);
  }
  ledger_.fail_everything(loss == LinkLoss::unanswered ? CommandError::timeout
                          : loss == LinkLoss::bus_down ? CommandError::bus_down
                                                       : CommandError::cancelled);
}

void HandDriver::on_link_down(TimePoint now) {
  lose_link(now, LinkLoss::bus_down, "bus down");
  flush(now);
}

void HandDriver::on_link_up(TimePoint now) {
  consecutive_timeouts_ = 0;
  // Probe at once, but not sooner than the pacing allows after the last frame
  // sent before the link went down (slot_.paced_until() is kept).
  if (auto* offline = std::get_if<Offline>(&link_)) offline->next_probe_at = now;
  flush(now);
}

void HandDriver::shut_down(TimePoint now) {
  lose_link(now, LinkLoss::shutdown, "service stopping");
  flush(now);
}

// ---------------------------------------------------------------------------
// Time

void HandDriver::on_time(TimePoint now) {
  if (const auto expired = slot_.expire(now)) on_timeout(*expired, now);
  on_init_deadlines(now);
  if (const MotionWaiter* waiter = ledger_.motion_waiter(); waiter && now >= waiter->deadline) {
    set_error(CommandError::timeout, fmt::format("{} did not end (caught or arrived) in time",
                                                 to_string(waiter->job.command.kind)));
    ledger_.finish_motion_waiter(fail(CommandError::timeout));
  }
  // Commands with their own timeout that are still waiting for their turn.
  ledger_.expire_queued(now);
  flush(now);
}

void HandDriver::on_init_deadlines(TimePoint now) {
  if (const Initializing* init = initializing(); init && now >= init->deadline) {
    set_init(NotInitialized{});
    const std::string why = fmt::format(
        "initialization did not finish within {} ms",
        std::chrono::duration_cast<std::chrono::milliseconds>(options_.init_timeout).count());
    emit(EventKind::init_failed, now, 0, why);
    set_error(CommandError::failed, why);
    ledger_.finish_init_waiter(fail(CommandError::failed));
  }
  if (const InitWaiter* waiter = ledger_.init_waiter(); waiter && now >= waiter->deadline) {
    set_error(CommandError::timeout, "initialization did not finish within the command's timeout");
    ledger_.finish_init_waiter(fail(CommandError::timeout));
  }
}

void HandDriver::on_timeout(const FrameSlot::Expired& expired, TimePoint now) {
  const InFlight& lost = expired.lost;
  counters_.count_timeout();
  ++consecutive_timeouts_;

  if (expired.resent) {
    counters_.count_retry();
  } else if (lost.purpose == Purpose::job && active()) {
    set_error(CommandError::timeout, fmt::format("no answer to {} after {} tries",
                                                 protocol::describe(lost.message), lost.attempts));
    ledger_.finish_active(fail(CommandError::timeout));
  } else if (lost.purpose == Purpose::confirm_position) {
    fingers_.read_lost();
    on_position_confirmed();  // with the position as last read
  } else if (lost.purpose == Purpose::confirm_rotation) {
    rotation_.read_lost();
  } else if (lost.purpose == Purpose::probe && state_.read_at == TimePoint{} && !anonymous_ &&
             !state_.last_error) {
    // Configured, and silent since the service started: said once, as the
    // hand's error, until it answers (on_answer).
    const std::string why = "never answered (powered? on this bus? this CAN ID and baud rate?)";
    spdlog::warn("{}: configured hand {} on bus {} {}", label(), state_.can_id, context_.bus_name,
                 why);
    set_error(CommandError::timeout, why);
  }
  // Polls and probes are simply read again later.
  if (online() && !anonymous_ && consecutive_timeouts_ >= options_.offline_after_timeouts) {
    lose_link(now, LinkLoss::unanswered,
              fmt::format("{} requests in a row went unanswered", consecutive_timeouts_));
  }
}

std::optional<TimePoint> HandDriver::next_wakeup() const {
  std::optional<TimePoint> earliest;
  auto consider = [&](TimePoint t) {
    if (!earliest || t < *earliest) earliest = t;
  };
  const Initializing* init = initializing();
  if (holding_for_group()) {
    // Its group wakes the loop when the release instant is fixed (or the
    // group is abandoned); the loop's longest idle wait covers its deadline.
    if (const auto release = active()->job.command.group->release_at())
      consider(std::max(*release, slot_.paced_until()));
  } else if (const InFlight* flying = slot_.in_flight()) {
    consider(flying->deadline);
  } else {
    if (has_command_frame()) consider(slot_.paced_until());
    if (anonymous_) {
      // never polled or probed
    } else if (const auto* offline = std::get_if<Offline>(&link_)) {
      consider(std::max(slot_.paced_until(), offline->next_probe_at));
    } else if (const Online* on = online(); fingers_.read_due() || rotation_.read_due() ||
                                            (init && init->check_now) || !on->refresh.empty()) {
      consider(slot_.paced_until());
    } else {
      if (auto due = next_poll_due(poll_plan(), on->poll.last_read)) {
        consider(std::max(slot_.paced_until(), *due));
      }
      if (init) consider(std::max(slot_.paced_until(), init->next_check_at));
    }
  }
  if (init) consider(init->deadline);
  if (const auto deadline = ledger_.next_deadline()) consider(*deadline);
  return earliest;
}

// ---------------------------------------------------------------------------
// Reporting

void HandDriver::set_error(CommandError error, std::string message) {
  state_.last_error = error;
  state_.last_error_message = std::move(message);
}

void HandDriver::emit(EventKind kind, TimePoint now, std::int32_t value, std::string message) {
  const std::optional<std::int32_t> last_read =
      state_.position >= 0 ? std::optional(state_.position) : std::nullopt;
  emit_event(kind, now, value, std::move(message), last_read, state_.target_position);
}

void HandDriver::emit_event(EventKind kind, TimePoint now, std::int32_t value, std::string message,
                            std::optional<std::int32_t> position, std::int32_t target) {
  if (anonymous_) return;
  HandEvent event;
  event.kind = kind;
  event.can_id = state_.can_id;
  event.time = now;
  event.position = position;
  event.target = target;
  event.value = value;
  event.message = std::move(message);
  spdlog::info("{}: {}{}{}", label(), to_string(kind), event.message.empty() ? "" : ": ",
               event.message);
  outbox_.add_event(std::move(event));
}

void HandDriver::publish_now(TimePoint now) {
  if (anonymous_) return;
  outbox_.publish_again();
  flush(now);
}

}  // namespace dh3::hand
