// CommandLedger: a hand's commands from their arrival to their one result.

#include "command_ledger.hpp"

#include <fmt/format.h>

#include <utility>

#include "dh3/hand/command_validation.hpp"
#include "dh3/hand/group_release.hpp"

namespace dh3::hand {

CommandLedger::CommandLedger(std::atomic<int>& queued, HandCounters& counters, HandOutbox& outbox,
                             std::string label)
    : queued_(queued), counters_(counters), outbox_(outbox), label_(std::move(label)) {}

void CommandLedger::add(DriverJob job) {
  const Command& command = job.command;
  if (command.kind == CommandKind::stop) {
    cancel_motion(true, true);
    queue_.push_front(std::move(job));
  } else {
    cancel_motion(moves_fingers(command), moves_rotation(command));
    queue_.push_back(std::move(job));
  }
}

void CommandLedger::cancel_motion(bool fingers, bool rotation) {
  if (!fingers && !rotation) return;
  for (auto it = queue_.begin(); it != queue_.end();) {
    const bool superseded =
        (fingers && moves_fingers(it->command)) || (rotation && moves_rotation(it->command));
    if (superseded) {
      complete(*it, fail(CommandError::cancelled));
      queued_.fetch_sub(1);
      it = queue_.erase(it);
    } else {
      ++it;
    }
  }
  if (active_ && !active_->motion_sent &&
      ((fingers && moves_fingers(active_->job.command)) ||
       (rotation && moves_rotation(active_->job.command)))) {
    // Its frame in flight, if any, still gets its reply; the job is over.
    finish_active(fail(CommandError::cancelled));
  }
  if (fingers) finish_motion_waiter(fail(CommandError::cancelled));
}

std::optional<DriverJob> CommandLedger::take_next(TimePoint now) {
  while (!queue_.empty()) {
    DriverJob job = std::move(queue_.front());
    queue_.pop_front();
    queued_.fetch_sub(1);
    if (job.command.timeout && now >= job.submitted + *job.command.timeout) {
      complete(job, fail(CommandError::timeout));
      continue;
    }
    return job;
  }
  return std::nullopt;
}

void CommandLedger::active_waits_for_init(TimePoint deadline) {
  finish_init_waiter(fail(CommandError::cancelled));
  init_waiter_ = InitWaiter{std::move(active_->job), deadline};
  active_.reset();
}

void CommandLedger::active_waits_for_motion(TimePoint deadline, std::uint64_t epoch) {
  finish_motion_waiter(fail(CommandError::cancelled));
  motion_waiter_ = MotionWaiter{std::move(active_->job), deadline, epoch, std::nullopt};
  active_.reset();
}

void CommandLedger::finish_active(const CommandResult& result) {
  if (!active_) return;
  complete(active_->job, result);
  active_.reset();
}

void CommandLedger::finish_init_waiter(const CommandResult& result) {
  if (!init_waiter_) return;
  complete(init_waiter_->job, result);
  init_waiter_.reset();
}

void CommandLedger::finish_motion_waiter(const CommandResult& result) {
  if (!motion_waiter_) return;
  complete(motion_waiter_->job, result);
  motion_waiter_.reset();
}

void CommandLedger::fail_everything(CommandError error) {
  if (active_) finish_active(fail(error));
  while (!queue_.empty()) {
    complete(queue_.front(), fail(error));
    queued_.fetch_sub(1);
    queue_.pop_front();
  }
  finish_init_waiter(fail(error));
  finish_motion_waiter(fail(error));
}

void CommandLedger::complete(DriverJob& job, const CommandResult& result) {
  counters_.count_command(job.command, result);
  if (!result && job.command.group) {
    // Too late once released (ignored then); before, no member may move.
    job.command.group->abandon(fmt::format("{}: {} ended {}", label_, to_string(job.command.kind),
                                           to_string(result.error())));
  }
  outbox_.add_completion(std::move(job.done), result, job.submitted);
}

void CommandLedger::expire_queued(TimePoint now) {
  for (auto it = queue_.begin(); it != queue_.end();) {
    if (it->command.timeout && now >= it->submitted + *it->command.timeout) {
      complete(*it, fail(CommandError::timeout));
      queued_.fetch_sub(1);
      it = queue_.erase(it);
    } else {
      ++it;
    }
  }
}

std::optional<TimePoint> CommandLedger::next_deadline() const {
  std::optional<TimePoint> earliest;
  auto consider = [&](TimePoint t) {
    if (!earliest || t < *earliest) earliest = t;
  };
  if (init_waiter_) consider(init_waiter_->deadline);
  if (motion_waiter_) consider(motion_waiter_->deadline);
  for (const DriverJob& job : queue_) {
    if (job.command.timeout) consider(job.submitted + *job.command.timeout);
  }
  return earliest;
}

}  // namespace dh3::hand
