#pragma once
// What both of dh3-sim's transports share: the hands and their stepping, the
// frames waiting for their time, the interval check, the control channel, the
// stop request and the poll loop. A transport (the TCP transfer box, a CAN
// interface) plugs into it through SimTransport: it adds its descriptors to the
// loop, hands received requests to receive(), and sends what the host gives it.
//
// The control channel (a file descriptor, stdin for dh3-sim) takes one command
// per line and answers each with one line starting with "ok" or "error"; see
// kControlHelp. The answers let a test know the command took effect before it
// sends its next frame.
//
// Threading: run() serves everything on the calling thread with poll(); only
// request_stop() may be called from elsewhere (also from a signal handler).

#include <poll.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <queue>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/base/fd_util.hpp"
#include "dh3/base/result.hpp"
#include "dh3/protocol/codec.hpp"
#include "dh3/sim/hand_set.hpp"
#include "dh3/sim/interval_watch.hpp"
#include "dh3/sim/replay_hands.hpp"
#include "dh3/sim/replay_script.hpp"
#include "dh3/sim/sim_hand.hpp"

namespace dh3::sim {

/// A frame's destination: the peer number a transport gave with the request it
/// answers, or this for every peer (unsolicited frames, and every frame on CAN).
inline constexpr std::uint64_t kEveryPeer = 0;

/// The control commands, for --help.
extern const std::string_view kControlHelp;

/// One way of reaching the simulated hands. The host calls these on run()'s thread.
class SimTransport {
 public:
  virtual ~SimTransport() = default;
  /// Appends the descriptors to wait on in this round of the loop.
  virtual void add_poll_fds(std::vector<pollfd>& fds) = 0;
  /// What poll() reported for them (the same entries, in the same order).
  virtual void on_poll(std::span<const pollfd> fds) = 0;
  /// Sends one frame to `destination` (kEveryPeer or a peer number).
  virtual void send(std::uint64_t destination, const protocol::Message& message) = 0;
  /// After a batch of send() calls.
  virtual void flush() {}
  /// When the transport wants on_timer() called (a reopen), or nullopt.
  [[nodiscard]] virtual std::optional<TimePoint> next_timer() const { return std::nullopt; }
  virtual void on_timer(TimePoint /*now*/) {}
  /// A control command only this transport knows: its answer, or nullopt if
  /// `words` is not one of its commands.
  virtual std::optional<std::string> execute_own(std::span<const std::string_view> /*words*/) {
    return std::nullopt;
  }
  /// run() is ending.
  virtual void on_stop() {}
};

struct SimHostOptions {
  std::vector<SimHandOptions> hands;
  /// Control commands come from here, one per line; -1: no control channel.
  /// End of file closes the channel, the host goes on.
  int control_in = -1;
  /// Answers to control commands go here, one line each; -1: not written.
  int control_out = -1;
  /// Frames to one hand closer together than this are interval violations
  /// (see IntervalWatch); zero: not checked.
  Duration min_interval = Duration::zero();
  /// Time frames for the interval check by the kernel's receive timestamp
  /// (see dh3/bus/receive_timestamp.hpp), not by when the loop read them. Tests that
  /// drive the check with a FakeClock turn it off.
  bool kernel_timestamps = true;
  /// Serve the hands of this recording (ReplayHands) instead of `hands`; the
  /// world commands (drop, object, mute, ...) are refused meanwhile.
  std::shared_ptr<const ReplayScript> replay;
};

class SimHost {
 public:
  SimHost(SimHostOptions options, const Clock& clock);
  SimHost(const SimHost&) = delete;
  SimHost& operator=(const SimHost&) = delete;

  /// Creates the wake-up pipe; fails with the OS's reason if it refuses.
  [[nodiscard]] Result<void, std::string> start();

  /// Serves `transport`, the hands and the control channel until
  /// request_stop() or a `quit` command; then calls transport.on_stop().
  void run(SimTransport& transport);
  /// Makes run() return soon. Any thread; async-signal-safe.
  void request_stop();
  [[nodiscard]] bool stop_requested() const { return stop_requested_.load(); }

  /// A request a transport received from peer `from`. `received` is when it
  /// arrived, in the timebase the transport keeps for it (the kernel's receive
  /// timestamp); nullopt: now, by the clock. The replies go to `from`, any
  /// unsolicited frames to every peer. Returns how many hands it reached.
  std::size_t receive(const protocol::Message& request, std::uint64_t from,
                      std::optional<Duration> received = std::nullopt);
  /// Sends every frame that is due through `transport`.
  void serve_due(SimTransport& transport);

  /// Executes one control command and returns its answer line (no newline).
  /// Only on run()'s thread, or while run() is not running.
  std::string execute(std::string_view command, SimTransport& transport);

  [[nodiscard]] std::size_t hand_count() const { return ids().size(); }
  [[nodiscard]] bool interval_check_enabled() const { return watch_.enabled(); }
  /// Interval violations over all hands so far.
  [[nodiscard]] std::uint64_t interval_violations() const { return watch_.violations(); }
  [[nodiscard]] const Clock& clock() const { return clock_; }

 private:
  /// A frame to send at `due`.
  struct Scheduled {
    TimePoint due;
    std::uint64_t sequence = 0;
    std::uint64_t destination = kEveryPeer;
    protocol::Message message;
  };
  struct ScheduledLater {
    bool operator()(const Scheduled& a, const Scheduled& b) const {
      return a.due != b.due ? a.due > b.due : a.sequence > b.sequence;
    }
  };

  void schedule(const std::vector<Outgoing>& frames, std::uint64_t destination);
  [[nodiscard]] int poll_timeout_ms(TimePoint now, std::optional<TimePoint> timer) const;
  void read_control(SimTransport& transport);
  void answer_control(const std::string& line);
  /// The hand answering on `id`, advanced to now (its unsolicited frames scheduled).
  SimHand* hand_now(std::uint8_t id);
  /// The CAN IDs answered on, ascending: the simulated hands' or the recording's.
  [[nodiscard]] std::vector<std::uint8_t> ids() const;
  [[nodiscard]] bool answers_on(std::uint8_t id) const;
  std::string execute_for_hand(std::span<const std::string_view> words, const std::string& echo);

  SimHostOptions options_;
  const Clock& clock_;
  HandSet hands_;
  std::optional<ReplayHands> replay_;  ///< set: it answers instead of hands_
  IntervalWatch watch_;
  UniqueFd wake_read_;  // the stop request's wake-up pipe
  UniqueFd wake_write_;
  std::atomic<bool> stop_requested_{false};
  std::priority_queue<Scheduled, std::vector<Scheduled>, ScheduledLater> scheduled_;
  std::uint64_t next_sequence_ = 0;
  std::vector<Outgoing> replies_;      // scratch
  std::vector<Outgoing> unsolicited_;  // scratch
  std::string control_buffer_;
};

}  // namespace dh3::sim
