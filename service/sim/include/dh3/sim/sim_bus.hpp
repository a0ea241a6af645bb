#pragma once
// In-process simulated hands on a simulated CAN bus. A first-class backend:
// `dh3-service` with no config runs on it. It implements the bus layer's
// interface from above it, as ros2_control's mock components sit above
// hardware_interface: the bus layer knows no simulator, and dh3-service's app
// layer makes a SimBus where the configuration asks for one (bus_setup.cpp). Frames sent are handed
// to the simulated hand with that CAN ID; its replies become receivable after the hand's reply
// delay and, optionally, the CAN bit time of the frames at the configured bit rate (111 bits per
// 8-byte frame without stuffing, up to 135 with worst-case stuffing).
//
// With a FakeClock, time moves only when the test advances it: receive() with a
// zero timeout returns what is due at clock.now(), so tests never sleep.
//
// The line model (bit_rate > 0): each frame occupies the line for
// bits_per_frame / bit_rate seconds, frames never overlap. A frame waits until
// the line is free; when several wait, the lowest CAN ID wins, as in CAN
// arbitration (ties: the one ready first). A sent request reaches the addressed
// hand when it has crossed the line; the hand's reply becomes ready after the
// hand's reply delay, then waits for the line in turn; it is receivable once it
// has crossed. With bit_rate 0 frames take no time: a reply is receivable after
// the reply delay. With tx_queue_length > 0, send() returns would_block while
// that many sent frames still wait for the line (a CAN controller's queue).
// A frame to ID 0 reaches every hand; only the CAN ID register is answered.
// A payload the hands cannot decode (read/write byte not 00/01) is ignored.
//
// Thread-safety: send() and receive() from the bus's I/O loop; wake(),
// with_hand(), add_hand(), remove_hand(), set_link_up() and the counters from
// any thread (one mutex).

#include <array>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <queue>
#include <string>
#include <vector>

#include "dh3/bus/bus.hpp"
#include "dh3/sim/hand_set.hpp"
#include "dh3/sim/sim_hand.hpp"

namespace dh3::sim {

struct SimBusOptions {
  /// 0: frames take no bus time. Otherwise replies are delayed by the time the
  /// request and reply occupy the line, and frames queue behind each other.
  std::uint32_t bit_rate = 0;
  /// Bits per frame when bit_rate is set (111 unstuffed .. 135 worst case).
  std::uint32_t bits_per_frame = 111;
  /// With bit_rate set: how many sent frames may wait for the line before
  /// send() says would_block; 0 = no limit.
  std::size_t tx_queue_length = 0;
  /// With bit_rate set: told of every frame as it leaves the line (`request`:
  /// sent through send(); else a hand's), with when it took the line and when
  /// it left it, like a bus monitor's timestamps (benchmarks). Called under
  /// the bus's lock: it must not block or call the bus.
  std::function<void(const bus::CanFrame& frame, TimePoint started, TimePoint ended, bool request)>
      on_line = nullptr;
};

class SimBus final : public bus::Bus {
 public:
  SimBus(std::string spec, std::vector<SimHandOptions> hands, const Clock& clock,
         SimBusOptions options = {});
  ~SimBus() override;

  [[nodiscard]] const std::string& spec() const override { return spec_; }
  Result<void, bus::BusError> send(const bus::CanFrame& frame) override;
  Result<void, bus::BusError> receive(std::vector<bus::CanFrame>& out, Duration timeout) override;
  void wake() override;
  [[nodiscard]] bus::LinkState link_state() const override;
  [[nodiscard]] std::uint32_t bit_rate() const override { return options_.bit_rate; }

  /// Runs `action` on the simulated hand with this CAN ID under the bus's lock
  /// (fault injection, placing or dropping objects, reading its true state).
  /// The hand is first advanced to clock.now(), so the injection happens now.
  /// If the action reboots the hand onto a new ID, it is found under that ID
  /// afterwards. Returns false if there is no such hand.
  bool with_hand(std::uint8_t id, const std::function<void(SimHand&)>& action);
  /// Adds a hand while running (a hand plugged in later).
  void add_hand(const SimHandOptions& options);
  /// Removes a hand (unplugged): it stops answering.
  void remove_hand(std::uint8_t id);
  /// Simulates the link going down and coming back: while down, send() and
  /// receive() return link_down and replies in flight are lost.
  void set_link_up(bool up);

  /// Frames seen on the bus, for tests and benchmarks.
  [[nodiscard]] std::uint64_t frames_sent() const;
  [[nodiscard]] std::uint64_t frames_delivered() const;

 private:
  /// Something that happens on the simulated bus at a given time.
  struct Event {
    enum class Kind : std::uint8_t {
      reply_ready,  ///< a hand is ready to put `frame` on the line
      line_done,    ///< `frame` has crossed the line
      hand_timer,   ///< a hand may have an unsolicited frame (initialization end)
      arbitrate,    ///< the line may be free: the best waiting frame takes it
    };
    TimePoint at;
    std::uint64_t sequence = 0;  ///< ties are served in the order they were made
    Kind kind = Kind::reply_ready;
    bool is_request = false;   ///< for line_done: sent by us (true) or by a hand
    std::uint8_t hand_id = 0;  ///< for hand_timer
    bus::CanFrame frame;
  };
  struct EventLater {
    bool operator()(const Event& a, const Event& b) const {
      if (a.at != b.at) return a.at > b.at;
      // Arbitration comes last among simultaneous events, so that every frame
      // ready at that instant takes part in it.
      const bool a_arbitrates = a.kind == Event::Kind::arbitrate;
      const bool b_arbitrates = b.kind == Event::Kind::arbitrate;
      if (a_arbitrates != b_arbitrates) return a_arbitrates;
      return a.sequence > b.sequence;
    }
  };
  /// A frame waiting for the line; the lowest CAN ID wins arbitration.
  struct Contender {
    bus::CanFrame frame;
    std::uint64_t sequence = 0;
    bool is_request = false;
  };
  struct ContenderLoses {
    bool operator()(const Contender& a, const Contender& b) const {
      return a.frame.id != b.frame.id ? a.frame.id > b.frame.id : a.sequence > b.sequence;
    }
  };
  struct Pending {
    TimePoint due;
    bus::CanFrame frame;
  };

  void push_event(Event event);
  /// Plays every event up to `now` in time order: hands handle requests at the
  /// time they have crossed the line, replies take the line when it is free.
  void process_until_locked(TimePoint now);
  void play_locked(const Event& event);
  /// A request reaches the hands at `at`; their replies are scheduled.
  void reach_hands_locked(TimePoint at, const bus::CanFrame& frame);
  void schedule_locked(TimePoint not_before, std::vector<Outgoing>& frames);
  void arm_timer_locked(const SimHand& hand);
  void contend_locked(TimePoint at, const bus::CanFrame& frame, bool is_request);
  void request_arbitration_locked(TimePoint at);
  void start_next_frame_locked(TimePoint at);
  void deliver_locked(TimePoint due, const bus::CanFrame& frame);
  void collect_due_locked(TimePoint now, std::vector<bus::CanFrame>& out);
  void drop_in_flight_locked();
  [[nodiscard]] std::optional<TimePoint> next_activity_locked() const;

  std::string spec_;
  const Clock& clock_;
  SimBusOptions options_;
  Duration frame_time_{};
  bool fake_time_ = false;  // the clock is not the system clock: wait in short slices
  mutable std::mutex mutex_;
  std::condition_variable wakeup_;
  bool woken_ = false;
  bool link_up_ = true;
  HandSet hands_;
  std::priority_queue<Event, std::vector<Event>, EventLater> events_;
  std::priority_queue<Contender, std::vector<Contender>, ContenderLoses> contenders_;
  std::size_t requests_waiting_ = 0;  // our frames among contenders_
  bool line_busy_ = false;
  std::array<std::optional<TimePoint>, 256> timer_armed_at_{};
  std::uint64_t next_sequence_ = 0;
  std::vector<Outgoing> scratch_;  // frames of the hand being served
  std::deque<Pending> in_flight_;  // crossed the line, ordered by due time
  std::uint64_t frames_sent_ = 0;
  std::uint64_t frames_delivered_ = 0;
};

}  // namespace dh3::sim
