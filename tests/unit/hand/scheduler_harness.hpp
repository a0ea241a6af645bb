#pragma once
// A BusScheduler on simulated hands with a FakeClock: time moves only when the
// test says, one millisecond per step, so every test is deterministic and none
// sleeps. The bus is wrapped to record every frame sent, with its time.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/hand/bus_scheduler.hpp"
#include "dh3/protocol/codec.hpp"
#include "dh3/sim/sim_bus.hpp"

namespace dh3::hand::test {

using namespace std::chrono_literals;
namespace reg = protocol::reg;

/// What the scheduler sent and when; forwards everything to the real bus.
class RecordingBus final : public bus::Bus {
 public:
  struct Sent {
    TimePoint at;
    protocol::Message message;
  };

  RecordingBus(std::unique_ptr<bus::Bus> inner, const Clock& clock)
      : inner_(std::move(inner)), clock_(clock) {}

  const std::string& spec() const override { return inner_->spec(); }
  Result<void, bus::BusError> send(const bus::CanFrame& frame) override {
    if (refuse_sends_ > 0) {
      --refuse_sends_;
      return fail(bus::BusError::would_block);
    }
    auto result = inner_->send(frame);
    if (result) {
      auto message = protocol::decode_payload(static_cast<std::uint8_t>(frame.id),
                                              std::span(frame.data.data(), frame.length));
      EXPECT_TRUE(message.ok()) << "the scheduler sent an undecodable frame";
      if (message) sent.push_back(Sent{clock_.now(), *message});
    }
    return result;
  }
  /// Records each burst's size; takes at most what limit_next_burst() allows.
  Result<std::size_t, bus::BusError> send_burst(std::span<const bus::CanFrame> frames) override {
    bursts.push_back(frames.size());
    const std::size_t room = std::min(frames.size(), burst_room_);
    burst_room_ = SIZE_MAX;
    if (room == 0 && !frames.empty()) return fail(bus::BusError::would_block);
    return Bus::send_burst(frames.first(room));
  }
  Result<void, bus::BusError> receive(std::vector<bus::CanFrame>& out, Duration timeout) override {
    const std::size_t before = out.size();
    auto result = inner_->receive(out, timeout);
    for (const auto& extra : injected_) out.push_back(extra);
    injected_.clear();
    received += out.size() - before;
    return result;
  }
  void wake() override { inner_->wake(); }
  bus::LinkState link_state() const override { return inner_->link_state(); }
  std::uint32_t bit_rate() const override { return inner_->bit_rate(); }

  /// The next `count` sends answer would_block (a full controller queue).
  void refuse_next_sends(int count) { refuse_sends_ = count; }
  /// The next send_burst() takes only the first `room` frames (a full queue).
  void limit_next_burst(std::size_t room) { burst_room_ = room; }
  /// A frame that appears on the bus as if some device sent it.
  void inject(const protocol::Message& message) {
    bus::CanFrame frame;
    frame.id = message.hand_id;
    frame.data = protocol::encode_payload(message);
    injected_.push_back(frame);
  }

  std::vector<Sent> sent;
  std::vector<std::size_t> bursts;  ///< the size of each send_burst() asked for
  std::size_t received = 0;

 private:
  std::unique_ptr<bus::Bus> inner_;
  const Clock& clock_;
  int refuse_sends_ = 0;
  std::size_t burst_room_ = SIZE_MAX;
  std::vector<bus::CanFrame> injected_;
};

class RecordingObserver final : public HandObserver {
 public:
  void on_state(const HandState& state) override {
    states.push_back(state);
    if (while_publishing) while_publishing();
  }
  void on_fresh(const HandState& state) override { fresh.push_back(state); }
  void on_event(const HandEvent& event) override { events.push_back(event); }
  void on_link(bus::LinkState state) override { links.push_back(state); }
  void on_batch_end(std::uint8_t can_id) override {
    batch_ends.push_back(BatchEnd{can_id, states.size(), fresh.size()});
  }

  [[nodiscard]] std::vector<HandEvent> events_of(EventKind kind, std::uint8_t id = 0) const {
    std::vector<HandEvent> found;
    for (const auto& e : events) {
      if (e.kind == kind && (id == 0 || e.can_id == id)) found.push_back(e);
    }
    return found;
  }
  [[nodiscard]] std::optional<HandState> last_state(std::uint8_t id) const {
    for (auto it = states.rbegin(); it != states.rend(); ++it) {
      if (it->can_id == id) return *it;
    }
    return std::nullopt;
  }

  std::vector<HandState> states;
  /// on_fresh: the published values read again, with a newer read_at.
  std::vector<HandState> fresh;
  std::vector<HandEvent> events;
  std::vector<bus::LinkState> links;
  /// on_batch_end, with how many states and fresh states had been reported by then.
  struct BatchEnd {
    std::uint8_t can_id = 0;
    std::size_t states = 0;
    std::size_t fresh = 0;
  };
  std::vector<BatchEnd> batch_ends;
  /// Runs inside each on_state, on the loop thread: a slow publisher.
  std::function<void()> while_publishing;
};

inline sim::SimHandOptions sim_hand(std::uint8_t id) {
  sim::SimHandOptions options;
  options.id = id;
  options.init_time = 200ms;
  options.position_speed = 200.0;  // a full stroke in half a second
  options.rotation_speed = 200.0;
  options.store_delay = 50ms;
  return options;
}

inline std::vector<sim::SimHandOptions> sim_hands(const std::vector<std::uint8_t>& ids) {
  std::vector<sim::SimHandOptions> hands;
  for (std::uint8_t id : ids) hands.push_back(sim_hand(id));
  return hands;
}

inline std::vector<HandConfig> configs(const std::vector<std::uint8_t>& ids) {
  std::vector<HandConfig> hands;
  for (std::uint8_t id : ids) hands.push_back(HandConfig{id, {}});
  return hands;
}

/// Options for tests: the document's pacing, short enough deadlines that
/// failures are reached in a few simulated seconds.
inline SchedulerOptions test_options() {
  SchedulerOptions options;
  options.command_interval = 20ms;
  options.poll_interval_moving = 50ms;
  options.poll_interval_idle = 500ms;
  options.reply_timeout = 100ms;
  options.offline_probe_interval = 500ms;
  options.init_timeout = 2s;
  options.motion_timeout = 3s;
  options.discovery_interval = 0s;
  return options;
}

inline Command cmd(CommandKind kind, std::int32_t value = 0) {
  Command c;
  c.kind = kind;
  c.value = value;
  return c;
}
inline Command move(std::int32_t position) {
  return cmd(CommandKind::move_to, position);
}
inline Command grasp(std::int32_t force) {
  return cmd(CommandKind::grasp, force);
}
inline Command read(protocol::Register r) {
  Command c = cmd(CommandKind::read_register);
  c.reg = r;
  return c;
}
inline Command write(protocol::Register r, std::int32_t value) {
  Command c = cmd(CommandKind::write_register, value);
  c.reg = r;
  return c;
}

class SchedulerHarness {
 public:
  /// `sim` hands answer on the bus; `configured` hands are what the scheduler
  /// expects (empty: it discovers).
  SchedulerHarness(std::vector<sim::SimHandOptions> sim, std::vector<HandConfig> configured,
                   SchedulerOptions options = test_options(), sim::SimBusOptions bus_options = {}) {
    auto sim_bus = std::make_unique<sim::SimBus>("sim:test", std::move(sim), clock, bus_options);
    sim_bus_ = sim_bus.get();
    auto recording = std::make_unique<RecordingBus>(std::move(sim_bus), clock);
    bus_ = recording.get();
    scheduler = std::make_unique<BusScheduler>("bus0", std::move(recording), std::move(configured),
                                               options, clock, observer);
  }

  /// Advances time one millisecond per step for `duration`.
  void run_for(Duration duration) {
    const TimePoint until = clock.now() + duration;
    while (clock.now() < until) tick();
  }

  /// Steps until `done()` holds; false if `limit` of simulated time passed first.
  bool run_until(const std::function<bool()>& done, Duration limit = 20s) {
    const TimePoint until = clock.now() + limit;
    while (!done()) {
      if (clock.now() >= until) return false;
      tick();
    }
    return true;
  }

  /// Submits and steps until the command completes (or 30 simulated seconds).
  std::optional<CommandResult> call(std::uint8_t id, Command command) {
    std::optional<CommandResult> result;
    scheduler->submit(id, command, [&](const CommandResult& r) {
      EXPECT_FALSE(result.has_value()) << "a command completed twice";
      result = r;
    });
    run_until([&] { return result.has_value(); }, 30s);
    return result;
  }

  /// Every hand online and initialized.
  void bring_up(const std::vector<std::uint8_t>& ids) {
    ASSERT_TRUE(run_until([&] {
      for (auto id : ids) {
        auto s = state(id);
        if (!s || !s->online) return false;
      }
      return true;
    })) << "hands did not come online";
    for (auto id : ids) {
      auto result = call(id, cmd(CommandKind::initialize));
      ASSERT_TRUE(result && result->ok()) << "hand " << int(id) << " did not initialize";
    }
  }

  [[nodiscard]] std::optional<HandState> state(std::uint8_t id) const {
    for (const auto& s : scheduler->state()) {
      if (s.can_id == id) return s;
    }
    return std::nullopt;
  }

  /// Frames sent to a hand (optionally only to one register).
  [[nodiscard]] std::vector<RecordingBus::Sent> sent_to(
      std::uint8_t id, std::optional<protocol::Register> r = {}) const {
    std::vector<RecordingBus::Sent> out;
    for (const auto& s : bus_->sent) {
      if (s.message.hand_id == id && (!r || s.message.reg == *r)) out.push_back(s);
    }
    return out;
  }

  sim::SimBus& sim_bus() { return *sim_bus_; }
  /// Where the simulated hand `id`'s fingers are now (0-100).
  double sim_position(std::uint8_t id) {
    double position = 0;
    sim_bus_->with_hand(id, [&](sim::SimHand& hand) { position = hand.position(); });
    return position;
  }
  RecordingBus& recorder() { return *bus_; }
  [[nodiscard]] const RecordingBus& recorder() const { return *bus_; }

  FakeClock clock;
  RecordingObserver observer;
  std::unique_ptr<BusScheduler> scheduler;

 private:
  void tick() {
    clock.advance(1ms);
    scheduler->step();
  }

  sim::SimBus* sim_bus_ = nullptr;
  RecordingBus* bus_ = nullptr;
};

}  // namespace dh3::hand::test
