#pragma once
// In-process simulated hands on a simulated CAN bus. A first-class backend:
// `dh3-service` with no config runs on it. Frames sent are handed to the
// simulated hand with that CAN ID; its replies become receivable after the
// hand's reply delay and, optionally, the CAN bit time of the frames at the
// configured bit rate (111 bits per 8-byte frame without stuffing, up to 135
// with worst-case stuffing).
//
// With a FakeClock, time moves only when the test advances it: receive() with a
// zero timeout returns what is due at clock.now(), so tests never sleep.

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <condition_variable>
#include <string>
#include <vector>

#include "bus/bus.hpp"
#include "sim/sim_hand.hpp"

namespace dh3::bus {

struct SimBusOptions {
  /// 0: frames take no bus time. Otherwise replies are delayed by the time the
  /// request and reply occupy the line, and frames queue behind each other.
  std::uint32_t bit_rate = 0;
  /// Bits per frame when bit_rate is set (111 unstuffed .. 135 worst case).
  std::uint32_t bits_per_frame = 111;
};

class SimBus final : public Bus {
 public:
  SimBus(std::string spec, std::vector<sim::SimHandOptions> hands, const Clock& clock,
         SimBusOptions options = {});
  ~SimBus() override;

  [[nodiscard]] const std::string& spec() const override { return spec_; }
  Result<void, BusError> send(const CanFrame& frame) override;
  Result<void, BusError> receive(std::vector<CanFrame>& out, Duration timeout) override;
  void wake() override;
  [[nodiscard]] LinkState link_state() const override;
  [[nodiscard]] std::uint32_t bit_rate() const override { return options_.bit_rate; }

  /// Runs `action` on the simulated hand with this CAN ID under the bus's lock
  /// (fault injection, placing or dropping objects, reading its true state).
  /// Returns false if there is no such hand.
  bool with_hand(std::uint8_t id, const std::function<void(sim::SimHand&)>& action);
  /// Adds a hand while running (a hand plugged in later).
  void add_hand(const sim::SimHandOptions& options);
  /// Removes a hand (unplugged): it stops answering.
  void remove_hand(std::uint8_t id);
  /// Simulates the link going down and coming back: while down, send() and
  /// receive() return link_down and replies in flight are lost.
  void set_link_up(bool up);

  /// Frames seen on the bus, for tests and benchmarks.
  [[nodiscard]] std::uint64_t frames_sent() const;
  [[nodiscard]] std::uint64_t frames_delivered() const;

 private:
  struct Pending {
    TimePoint due;
    CanFrame frame;
  };
  void collect_due_locked(TimePoint now, std::vector<CanFrame>& out);

  std::string spec_;
  const Clock& clock_;
  SimBusOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable wakeup_;
  bool woken_ = false;
  bool link_up_ = true;
  std::map<std::uint8_t, std::unique_ptr<sim::SimHand>> hands_;
  std::deque<Pending> in_flight_;  // ordered by due time
  TimePoint line_free_at_{};
  std::uint64_t frames_sent_ = 0;
  std::uint64_t frames_delivered_ = 0;
};

}  // namespace dh3::bus
