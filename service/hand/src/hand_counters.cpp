#include "hand_counters.hpp"

#include <algorithm>
#include <numeric>

namespace dh3::hand {
namespace {

constexpr std::size_t kKinds = static_cast<std::size_t>(CommandKind::stop) + 1;
constexpr std::size_t kErrors = static_cast<std::size_t>(CommandError::failed) + 1;
static_assert(HandCounters::kResults == kErrors + 1, "OK plus every CommandError");

/// Writes the contract names a command of its own (in this order after the kinds).
constexpr protocol::Register kNamedWrites[] = {protocol::reg::kCanId, protocol::reg::kBaudRate,
                                               protocol::reg::kInitFeedback};
static_assert(HandCounters::kTypes == kKinds + std::size(kNamedWrites));

std::size_t type_index(const Command& command) {
  if (command.kind == CommandKind::write_register) {
    for (std::size_t i = 0; i < std::size(kNamedWrites); ++i) {
      if (command.reg == kNamedWrites[i]) return kKinds + i;
    }
  }
  return static_cast<std::size_t>(command.kind);
}

std::size_t result_index(const CommandResult& result) {
  return result ? 0 : 1 + static_cast<std::size_t>(result.error());
}

}  // namespace

std::uint64_t RoundTripHistogram::total() const {
  return std::accumulate(counts.begin(), counts.end(), std::uint64_t{0});
}

void HandCounters::count_command(const Command& command, const CommandResult& result) {
  commands_[type_index(command) * kResults + result_index(result)].fetch_add(
      1, std::memory_order_relaxed);
}

void HandCounters::observe_round_trip(Duration round_trip) {
  const auto bucket = static_cast<std::size_t>(
      std::lower_bound(kRoundTripBuckets.begin(), kRoundTripBuckets.end(), round_trip) -
      kRoundTripBuckets.begin());
  round_trip_[bucket].fetch_add(1, std::memory_order_relaxed);
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(round_trip).count();
  round_trip_ns_.fetch_add(static_cast<std::uint64_t>(std::max<std::int64_t>(ns, 0)),
                           std::memory_order_relaxed);
}

void HandCounters::snapshot(HandMetrics& out) const {
  out.commands.clear();
  for (std::size_t type = 0; type < kTypes; ++type) {
    for (std::size_t result = 0; result < kResults; ++result) {
      const auto count = commands_[type * kResults + result].load(std::memory_order_relaxed);
      if (count == 0) continue;
      CommandTally tally;
      if (type < kKinds) {
        tally.kind = static_cast<CommandKind>(type);
      } else {
        tally.kind = CommandKind::write_register;
        tally.reg = kNamedWrites[type - kKinds];
      }
      if (result > 0) tally.error = static_cast<CommandError>(result - 1);
      tally.count = count;
      out.commands.push_back(tally);
    }
  }
  out.timeouts = timeouts_.load(std::memory_order_relaxed);
  out.retries = retries_.load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < round_trip_.size(); ++i) {
    out.round_trip.counts[i] = round_trip_[i].load(std::memory_order_relaxed);
  }
  out.round_trip.sum_seconds =
      static_cast<double>(round_trip_ns_.load(std::memory_order_relaxed)) / 1e9;
}

void RecentFrames::roll(TimePoint now) {
  if (now < slot_start_ + kSlot) return;
  if (now >= slot_start_ + kSlot * static_cast<int>(kSlots + 1)) {
    // Idle (or not stepped) for longer than the window: everything in it is old.
    slots_.fill(0);
    slots_[0] = current_;
    next_slot_ = 1 % kSlots;
    filled_ = kSlots;
    slot_start_ = now;
  } else {
    while (now >= slot_start_ + kSlot) {
      slots_[next_slot_] = current_;
      next_slot_ = (next_slot_ + 1) % kSlots;
      filled_ = std::min(filled_ + 1, kSlots);
      current_ = 0;
      slot_start_ += kSlot;
    }
  }
  current_ = 0;
  const auto frames = std::accumulate(slots_.begin(), slots_.end(), std::uint64_t{0});
  const double seconds =
      std::chrono::duration<double>(kSlot).count() * static_cast<double>(filled_);
  per_second_.store(static_cast<double>(frames) / seconds, std::memory_order_relaxed);
}

}  // namespace dh3::hand
