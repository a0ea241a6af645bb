#include "dh3/sim/sim_bus.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <span>
#include <utility>

#include "dh3/protocol/codec.hpp"

namespace dh3::sim {

using bus::BusError;
using bus::CanFrame;
using bus::LinkState;

namespace {

constexpr std::uint32_t kMaxStandardId = 0x7FF;
constexpr std::uint8_t kMaxLength = 8;
// With a clock that is not the system clock, another thread may move time on
// while receive() waits; looking again this often keeps such tests prompt.
constexpr Duration kFakeTimeWaitSlice = std::chrono::milliseconds(1);

CanFrame to_frame(const protocol::Message& message) {
  return CanFrame{message.hand_id, static_cast<std::uint8_t>(protocol::kPayloadSize),
                  protocol::encode_payload(message)};
}

}  // namespace

SimBus::SimBus(std::string spec, std::vector<SimHandOptions> hands, const Clock& clock,
               SimBusOptions options)
    : spec_(std::move(spec)),
      clock_(clock),
      options_(options),
      fake_time_(dynamic_cast<const SystemClock*>(&clock) == nullptr) {
  if (options_.bit_rate > 0) {
    frame_time_ = std::chrono::duration_cast<Duration>(
        std::chrono::nanoseconds(static_cast<std::uint64_t>(options_.bits_per_frame) *
                                 1'000'000'000ULL / options_.bit_rate));
  }
  const TimePoint now = clock_.now();
  for (const SimHandOptions& hand : hands) {
    if (hands_.add(hand, now)) {
      spdlog::warn("sim bus {}: two hands with CAN ID {}, keeping the last", spec_, hand.id);
    }
  }
}

SimBus::~SimBus() = default;

Result<void, BusError> SimBus::send(const CanFrame& frame) {
  std::lock_guard lock(mutex_);
  if (!link_up_) return fail(BusError::link_down);
  if (frame.id > kMaxStandardId || frame.length > kMaxLength) {
    return fail(BusError::frame_invalid);
  }
  if (options_.bit_rate > 0 && options_.tx_queue_length > 0 &&
      requests_waiting_ >= options_.tx_queue_length) {
    return fail(BusError::would_block);
  }
  const TimePoint now = clock_.now();
  process_until_locked(now);
  ++frames_sent_;
  if (options_.bit_rate > 0) {
    contend_locked(now, frame, true);
  } else {
    reach_hands_locked(now, frame);
  }
  process_until_locked(now);
  return {};
}

Result<void, BusError> SimBus::receive(std::vector<CanFrame>& out, Duration timeout) {
  std::unique_lock lock(mutex_);
  const TimePoint deadline = SteadyClock::now() + timeout;
  for (;;) {
    if (!link_up_) return fail(BusError::link_down);
    const TimePoint now = clock_.now();
    process_until_locked(now);
    const std::size_t before = out.size();
    collect_due_locked(now, out);
    if (out.size() > before || woken_ || timeout <= Duration::zero()) {
      woken_ = false;
      return {};
    }
    const TimePoint real_now = SteadyClock::now();
    if (real_now >= deadline) return {};
    TimePoint wait_until = deadline;
    if (const std::optional<TimePoint> next = next_activity_locked()) {
      wait_until = std::min(wait_until, real_now + std::max(*next - now, Duration::zero()));
    }
    if (fake_time_) wait_until = std::min(wait_until, real_now + kFakeTimeWaitSlice);
    wakeup_.wait_until(lock, wait_until);
  }
}

void SimBus::wake() {
  {
    std::lock_guard lock(mutex_);
    woken_ = true;
  }
  wakeup_.notify_all();
}

LinkState SimBus::link_state() const {
  std::lock_guard lock(mutex_);
  return link_up_ ? LinkState::up : LinkState::down;
}

bool SimBus::with_hand(std::uint8_t id, const std::function<void(SimHand&)>& action) {
  {
    std::lock_guard lock(mutex_);
    const TimePoint now = clock_.now();
    process_until_locked(now);
    SimHand* hand = hands_.find(id);
    if (hand == nullptr) return false;
    // Bring the hand to now so the injection happens now, not at its last request.
    scratch_ = hand->advance(now);
    schedule_locked(now, scratch_);
    std::uint8_t id_after = id;
    hands_.with_hand(id, action, &id_after);
    if (const SimHand* moved = hands_.find(id_after)) arm_timer_locked(*moved);
    process_until_locked(now);
  }
  wakeup_.notify_all();
  return true;
}

void SimBus::add_hand(const SimHandOptions& options) {
  std::lock_guard lock(mutex_);
  const TimePoint now = clock_.now();
  process_until_locked(now);
  if (hands_.add(options, now)) {
    spdlog::warn("sim bus {}: hand {} replaced by a new one", spec_, options.id);
  }
}

void SimBus::remove_hand(std::uint8_t id) {
  std::lock_guard lock(mutex_);
  process_until_locked(clock_.now());
  hands_.remove(id);
}

void SimBus::set_link_up(bool up) {
  {
    std::lock_guard lock(mutex_);
    if (up == link_up_) return;
    // Play what happened until now in the old state: while down, frames that
    // crossed are lost; when going down, frames not yet received are lost.
    process_until_locked(clock_.now());
    link_up_ = up;
    if (!up) drop_in_flight_locked();
  }
  wakeup_.notify_all();
}

std::uint64_t SimBus::frames_sent() const {
  std::lock_guard lock(mutex_);
  return frames_sent_;
}

std::uint64_t SimBus::frames_delivered() const {
  std::lock_guard lock(mutex_);
  return frames_delivered_;
}

void SimBus::push_event(Event event) {
  event.sequence = next_sequence_++;
  events_.push(std::move(event));
}

void SimBus::process_until_locked(TimePoint now) {
  while (!events_.empty() && events_.top().at <= now) {
    const Event event = events_.top();
    events_.pop();
    play_locked(event);
  }
}

void SimBus::play_locked(const Event& event) {
  switch (event.kind) {
    case Event::Kind::reply_ready:
      if (!link_up_) return;  // the hand talks to a dead line
      if (options_.bit_rate > 0) {
        contend_locked(event.at, event.frame, false);
      } else {
        deliver_locked(event.at, event.frame);
      }
      return;
    case Event::Kind::line_done:
      line_busy_ = false;
      if (options_.on_line) {
        options_.on_line(event.frame, event.at - frame_time_, event.at, event.is_request);
      }
      if (event.is_request) {
        reach_hands_locked(event.at, event.frame);
      } else {
        deliver_locked(event.at, event.frame);
      }
      request_arbitration_locked(event.at);
      return;
    case Event::Kind::hand_timer: {
      if (timer_armed_at_[event.hand_id] == event.at) timer_armed_at_[event.hand_id].reset();
      SimHand* hand = hands_.find(event.hand_id);
      if (hand == nullptr) return;
      scratch_ = hand->advance(event.at);
      schedule_locked(event.at, scratch_);
      arm_timer_locked(*hand);
      return;
    }
    case Event::Kind::arbitrate:
      start_next_frame_locked(event.at);
      return;
  }
}

void SimBus::reach_hands_locked(TimePoint at, const CanFrame& frame) {
  // A DH-3 hand only understands 8-byte payloads on an ID it can have.
  if (frame.id > 0xFF || frame.length != protocol::kPayloadSize) return;
  const auto id = static_cast<std::uint8_t>(frame.id);
  const auto request = protocol::decode_payload(id, std::span(frame.data.data(), frame.length));
  if (!request) return;
  scratch_.clear();
  hands_.deliver(*request, at, scratch_, scratch_);
  schedule_locked(at, scratch_);
  if (id != 0) {
    if (const SimHand* hand = hands_.find(id)) arm_timer_locked(*hand);
    return;
  }
  for (const std::uint8_t each : hands_.ids()) arm_timer_locked(*hands_.find(each));
}

void SimBus::schedule_locked(TimePoint not_before, std::vector<Outgoing>& frames) {
  for (const Outgoing& outgoing : frames) {
    Event event;
    event.at = std::max(outgoing.due, not_before);
    event.kind = Event::Kind::reply_ready;
    event.frame = to_frame(outgoing.message);
    push_event(std::move(event));
  }
  frames.clear();
}

void SimBus::arm_timer_locked(const SimHand& hand) {
  const std::optional<TimePoint> at = hand.next_unsolicited_at();
  if (!at || timer_armed_at_[hand.id()] == at) return;
  timer_armed_at_[hand.id()] = at;
  Event event;
  event.at = *at;
  event.kind = Event::Kind::hand_timer;
  event.hand_id = hand.id();
  push_event(std::move(event));
}

void SimBus::contend_locked(TimePoint at, const CanFrame& frame, bool is_request) {
  contenders_.push(Contender{frame, next_sequence_++, is_request});
  if (is_request) ++requests_waiting_;
  request_arbitration_locked(at);
}

void SimBus::request_arbitration_locked(TimePoint at) {
  if (line_busy_) return;  // the frame on the line asks for it when done
  Event event;
  event.at = at;
  event.kind = Event::Kind::arbitrate;
  push_event(std::move(event));
}

void SimBus::start_next_frame_locked(TimePoint at) {
  if (line_busy_ || contenders_.empty()) return;
  const Contender winner = contenders_.top();
  contenders_.pop();
  if (winner.is_request) --requests_waiting_;
  line_busy_ = true;
  Event event;
  event.at = at + frame_time_;
  event.kind = Event::Kind::line_done;
  event.is_request = winner.is_request;
  event.frame = winner.frame;
  push_event(std::move(event));
}

void SimBus::deliver_locked(TimePoint due, const CanFrame& frame) {
  if (!link_up_) return;
  // Events play in time order, so this nearly always appends.
  auto position = in_flight_.end();
  while (position != in_flight_.begin() && std::prev(position)->due > due) --position;
  in_flight_.insert(position, Pending{due, frame});
}

void SimBus::collect_due_locked(TimePoint now, std::vector<CanFrame>& out) {
  while (!in_flight_.empty() && in_flight_.front().due <= now) {
    out.push_back(in_flight_.front().frame);
    in_flight_.pop_front();
    ++frames_delivered_;
  }
}

void SimBus::drop_in_flight_locked() {
  in_flight_.clear();
  contenders_ = {};
  requests_waiting_ = 0;
  line_busy_ = false;
  // The hands live on; only their timers survive.
  std::vector<Event> keep;
  while (!events_.empty()) {
    if (events_.top().kind == Event::Kind::hand_timer) keep.push_back(events_.top());
    events_.pop();
  }
  for (Event& event : keep) events_.push(std::move(event));
}

std::optional<TimePoint> SimBus::next_activity_locked() const {
  std::optional<TimePoint> next;
  if (!events_.empty()) next = events_.top().at;
  if (!in_flight_.empty() && (!next || in_flight_.front().due < *next)) {
    next = in_flight_.front().due;
  }
  return next;
}

}  // namespace dh3::sim
