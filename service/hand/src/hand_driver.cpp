// HandDriver: commands in, the hand's lifecycle (online, offline, link loss,
// shutdown), time (timeouts, deadlines, wake-ups) and reporting.

#include "hand_driver.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "dh3/hand/command_validation.hpp"
#include "dh3/hand/group_release.hpp"

namespace dh3::hand {
namespace {

namespace reg = protocol::reg;
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
  if (finger_motion_) {
    activity.fingers = finger_motion_->closing ? FingerActivity::closing : FingerActivity::opening;
  } else if (state_.grip == GripState::caught) {
    activity.fingers = FingerActivity::holding;
  }
  activity.rotating = rotation_motion_.has_value();
  activity.initializing = initializing() != nullptr;
  return plan_polls(activity,
                    PollIntervals{options_.poll_interval_watch, options_.poll_interval_moving,
                                  options_.poll_interval_idle});
}

void HandDriver::on_answer(TimePoint now) {
  consecutive_timeouts_ = 0;
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
  finger_motion_.reset();
  rotation_motion_.reset();
  end_of_motion_.read_due = false;
  end_of_motion_.recheck_arrival = false;
  end_of_rotation_.read_due = false;
  end_of_rotation_.recheck_arrival = false;
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
    end_of_motion_.recheck_arrival = false;  // the status is read again anyway
    on_position_confirmed();                 // with the position as last read
  } else if (lost.purpose == Purpose::confirm_rotation) {
    end_of_rotation_.recheck_arrival = false;
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
    } else if (const Online* on = online(); end_of_motion_.read_due || end_of_rotation_.read_due ||
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

void HandDriver::emit_rotation_event(EventKind kind, std::int32_t status, TimePoint now) {
  std::string message;
  if (kind == EventKind::rotation_blocked) {
    message = fmt::format("rotation blocked on the way to {} (last read at {})",
                          state_.rotation_target, state_.rotation);
  }
  emit(kind, now, status, std::move(message), state_.rotation, state_.rotation_target);
}

void HandDriver::emit(EventKind kind, TimePoint now, std::int32_t value, std::string message,
                      std::optional<std::int32_t> position, std::optional<std::int32_t> target) {
  if (anonymous_) return;
  HandEvent event;
  event.kind = kind;
  event.can_id = state_.can_id;
  event.time = now;
  event.position = position.value_or(state_.position);
  event.target = target.value_or(state_.target_position);
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
