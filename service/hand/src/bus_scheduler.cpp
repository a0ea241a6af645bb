#include "dh3/hand/bus_scheduler.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <mutex>
#include <thread>

#include "dh3/hand/command_validation.hpp"
#include "dh3/hand/group_release.hpp"
#include "dh3/protocol/codec.hpp"
#include "discovery_scan.hpp"
#include "hand_counters.hpp"
#include "hand_driver.hpp"
#include "id_zero_reservation.hpp"
#include "line_budget.hpp"
#include "link_monitor.hpp"

namespace dh3::hand {
namespace {

/// The longest the loop sleeps in receive() with nothing due, so that a
/// reconnecting backend is retried and stop() is noticed promptly.
constexpr Duration kMaxIdleWait = std::chrono::milliseconds(100);

bus::CanFrame to_frame(const protocol::Message& message) {
  bus::CanFrame frame;
  frame.id = message.hand_id;
  frame.length = 8;
  const auto payload = protocol::encode_payload(message);
  std::copy(payload.begin(), payload.end(), frame.data.begin());
  return frame;
}

}  // namespace

class BusScheduler::Impl {
 public:
  Impl(std::string bus_name, std::unique_ptr<bus::Bus> bus, std::vector<HandConfig> hands,
       SchedulerOptions options, const Clock& clock, HandObserver& observer)
      : name_(std::move(bus_name)),
        bus_(std::move(bus)),
        options_(options),
        clock_(clock),
        observer_(observer),
        roster_(hands),
        context_{
            options_, observer_, name_, roster_, unexpected_, latency_, [this] { bus_->wake(); }},
        bit_rate_(bus_->bit_rate()),
        link_(bus_->link_state()),
        line_(bit_rate_, options_.max_line_load),
        id_zero_(options_.frame_spacing()),
        scan_(DiscoveryOptions{hands.empty(), options_.discovery_interval, options_.probe_spacing,
                               options_.reply_timeout},
              clock_.now()) {
    const TimePoint now = clock_.now();
    for (HandConfig& hand : hands) {
      if (hand.can_id == 0 || drivers_[hand.can_id]) continue;
      add_driver(std::move(hand), now)->publish_now(now);
    }
  }

  ~Impl() {
    for (auto& counters : hand_counters_) delete counters.load();
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  // ---- any thread ----------------------------------------------------------

  void submit(std::uint8_t can_id, Command command, Completion done) {
    if (auto valid = validate(can_id, command, options_.allow_admin); !valid) {
      spdlog::debug("{}/{}: refused {}: {}", name_, can_id, to_string(command.kind),
                    valid.error().message);
      refuse(can_id, command, done, valid.error().error);
      return;
    }
    if (can_id != 0 && !roster_.knows(can_id)) {
      refuse(can_id, command, done, CommandError::unknown_hand);
      return;
    }
    if (queued_[can_id].fetch_add(1) >= static_cast<int>(options_.queue_capacity)) {
      queued_[can_id].fetch_sub(1);
      refuse(can_id, command, done, CommandError::busy);
      return;
    }
    {
      std::unique_lock lock(inbox_mutex_);
      if (!stopped_) {
        inbox_.push_back(
            Submitted{can_id, HandDriver::Job{std::move(command), std::move(done), clock_.now()}});
        lock.unlock();
        bus_->wake();
        return;
      }
    }
    queued_[can_id].fetch_sub(1);
    refuse(can_id, command, done, CommandError::cancelled);
  }

  void request_scan(ScanCompletion done) {
    {
      std::lock_guard lock(inbox_mutex_);
      if (!stopped_) {
        scan_requests_.push_back(std::move(done));
        bus_->wake();
        return;
      }
    }
    done({});
  }

  std::vector<HandState> state() const { return roster_.published(); }
  const HandRoster& roster() const { return roster_; }

  SchedulerCounters counters() const {
    SchedulerCounters out{frames_sent_.load(), frames_received_.load(), unexpected_.load(), 0, 0,
                          bus_errors_.load(),  link_.reconnects()};
    // Retries and timeouts are counted per hand only; the bus's are their sum.
    for (const auto& slot : hand_counters_) {
      if (const HandCounters* hand = slot.load(std::memory_order_acquire)) {
        out.retries += hand->retries();
        out.timeouts += hand->timeouts();
      }
    }
    return out;
  }

  BusMetrics metrics() const {
    BusMetrics out;
    out.bus = name_;
    out.link_up = link_.state() == bus::LinkState::up;
    out.counters = counters();
    out.bit_rate = bit_rate_;
    out.recent_frames_per_second = recent_frames_.frames_per_second();
    out.diagnostics = bus_->diagnostics();
    out.latency = latency_.snapshot();
    if (bit_rate_ > 0) {
      out.line_load_percent =
          100.0 * out.recent_frames_per_second * kBitsPerFrame / static_cast<double>(bit_rate_);
    }
    if (const HandCounters* anonymous = hand_counters_[0].load(std::memory_order_acquire)) {
      HandMetrics& hand = out.hands.emplace_back();
      anonymous->snapshot(hand);
    }
    for (const HandState& state : state()) {
      HandMetrics& hand = out.hands.emplace_back();
      hand.can_id = state.can_id;
      hand.name = state.name;
      hand.online = state.online;
      if (const HandCounters* counted =
              hand_counters_[state.can_id].load(std::memory_order_acquire)) {
        counted->snapshot(hand);
      }
    }
    return out;
  }

  const std::string& name() const { return name_; }
  bus::LinkState link_state() const { return link_.state(); }

  void warm(const std::vector<HandState>& seen) {
    const TimePoint now = clock_.now();
    for (const HandState& hand : seen) {
      HandDriver* driver = drivers_[hand.can_id].get();
      if (hand.can_id == 0 || driver == nullptr) continue;
      driver->warm(hand);
      driver->publish_now(now);
    }
  }

  void start() {
    if (running_.exchange(true)) return;
    thread_ = std::thread([this] { run(); });
  }

  void stop() {
    if (running_.exchange(false)) {
      bus_->wake();
      if (thread_.joinable()) thread_.join();
    }
    std::vector<Submitted> leftover;
    std::vector<ScanCompletion> scans;
    {
      std::lock_guard lock(inbox_mutex_);
      if (stopped_) return;
      stopped_ = true;
      leftover.swap(inbox_);
      scans.swap(scan_requests_);
    }
    const TimePoint now = clock_.now();
    for (Submitted& item : leftover) {
      queued_[item.can_id].fetch_sub(1);
      refuse(item.can_id, item.job.command, item.job.done, CommandError::cancelled);
    }
    for (std::uint8_t id : order_) drivers_[id]->shut_down(now);
    finish_scan();
    for (ScanCompletion& done : scans) done({});
  }

  // ---- counting (any thread) -------------------------------------------------

  HandCounters& counters_for(std::uint8_t can_id) {
    HandCounters* counters = hand_counters_[can_id].load(std::memory_order_acquire);
    if (counters) return *counters;
    auto fresh = std::make_unique<HandCounters>();
    if (hand_counters_[can_id].compare_exchange_strong(counters, fresh.get(),
                                                       std::memory_order_acq_rel)) {
      return *fresh.release();
    }
    return *counters;  // another thread was first
  }

  /// A command that ends before any driver has it. Commands to hands that do
  /// not exist are not counted: no hand's figures should grow from them.
  void refuse(std::uint8_t can_id, const Command& command, Completion& done, CommandError error) {
    if (command.group) {
      command.group->abandon(fmt::format("{}/{}: {} refused: {}", name_, can_id,
                                         to_string(command.kind), to_string(error)));
    }
    if (can_id == 0 || roster_.knows(can_id))
      counters_for(can_id).count_command(command, fail(error));
    done(fail(error));
  }

  // ---- loop thread ---------------------------------------------------------

  void step() { pass(Duration::zero()); }

  TimePoint next_wakeup() const {
    const TimePoint now = clock_.now();
    std::optional<TimePoint> earliest;
    auto consider = [&](TimePoint t) {
      if (!earliest || t < *earliest) earliest = t;
    };
    if (link_.up()) {
      for (std::uint8_t id : order_) {
        if (auto t = drivers_[id]->next_wakeup()) consider(line_.allows(*t) ? *t : line_.next_at());
      }
      if (auto t = scan_.next_wakeup()) consider(*t);
    }
    return earliest.value_or(now + kMaxIdleWait);
  }

 private:
  struct Submitted {
    std::uint8_t can_id = 0;
    HandDriver::Job job;
  };

  HandDriver* add_driver(HandConfig config, TimePoint now) {
    const std::uint8_t id = config.can_id;
    drivers_[id] = std::make_unique<HandDriver>(std::move(config), context_, queued_[id],
                                                counters_for(id), now, id == 0);
    order_.push_back(id);
    roster_.add(id);
    scan_.known(id);
    return drivers_[id].get();
  }

  void run() {
    spdlog::debug("{}: loop started on {}", name_, bus_->spec());
    while (running_.load()) {
      const Duration wait =
          std::clamp(next_wakeup() - clock_.now(), Duration::zero(), kMaxIdleWait);
      pass(wait);
    }
  }

  void pass(Duration wait) {
    frames_.clear();
    const auto received = bus_->receive(frames_, wait);
    const TimePoint now = clock_.now();
    recent_frames_.roll(now);
    recent_frames_.count(frames_.size());
    if (!received && received.error() == bus::BusError::io_error) bus_errors_.fetch_add(1);
    const bool link_lost = !received && received.error() == bus::BusError::link_down;
    on_link_change(link_lost ? link_.on_link_lost() : link_.on_reported(bus_->link_state()), now);
    drain_inbox(now);
    for (const bus::CanFrame& frame : frames_) on_frame(frame, now);
    for (std::uint8_t id : order_) drivers_[id]->on_time(now);
    scan_on_time(now);
    send_due(now);
  }

  void drain_inbox(TimePoint now) {
    std::vector<Submitted> items;
    std::vector<ScanCompletion> scans;
    {
      std::lock_guard lock(inbox_mutex_);
      items.swap(inbox_);
      scans.swap(scan_requests_);
    }
    for (Submitted& item : items) {
      if (!link_.up()) {
        queued_[item.can_id].fetch_sub(1);
        refuse(item.can_id, item.job.command, item.job.done, CommandError::bus_down);
        continue;
      }
      HandDriver* driver = drivers_[item.can_id].get();
      if (!driver) driver = add_driver(HandConfig{item.can_id, {}}, now);  // ID 0
      driver->enqueue(std::move(item.job), now);
    }
    for (ScanCompletion& done : scans) {
      if (!link_.up()) {
        done({});
        continue;
      }
      if (scan_.request(std::move(done), now)) {
        spdlog::debug("{}: probing CAN IDs 1-255 for hands", name_);
      }
    }
  }

  void on_frame(const bus::CanFrame& frame, TimePoint now) {
    frames_received_.fetch_add(1);
    if (frame.id > 0xFF || frame.length != protocol::kPayloadSize) {
      unexpected(fmt::format("frame with id 0x{:X} and length {}", frame.id, frame.length));
      return;
    }
    const auto id = static_cast<std::uint8_t>(frame.id);
    const auto message = protocol::decode_payload(id, frame.data);
    if (!message) {
      unexpected(
          fmt::format("undecodable frame from {}: {}", id, protocol::to_string(message.error())));
      return;
    }
    if (HandDriver* driver = drivers_[id].get()) {
      if (!driver->on_frame(*message, now)) unexpected(protocol::describe(*message));
      return;
    }
    if (message->reg == protocol::reg::kFirmwareVersion) {
      if (const auto probe_sent = scan_.answered(id)) {
        spdlog::info("{}: found a hand with CAN ID {}", name_, id);
        HandDriver* found = add_driver(HandConfig{id, {}}, now);
        // The probe was this hand's first frame: its own reads keep the interval to it.
        found->hold_sends_until(*probe_sent + options_.frame_spacing());
        found->on_discovered(*message, now);
        return;
      }
    }
    unexpected(protocol::describe(*message));
  }

  void unexpected(const std::string& what) {
    const auto count = unexpected_.fetch_add(1) + 1;
    // Counted always; logged sparingly, so a babbling device cannot flood the log.
    if (count <= 10 || count % 1000 == 0) {
      spdlog::warn("{}: unexpected frame ({} so far): {}", name_, count, what);
    }
  }

  void send_due(TimePoint pass_started) {
    if (!link_.up()) return;
    if (!send_group_frames()) return;
    reserve_for_id_zero(pass_started);
    const std::size_t n = order_.size();
    for (std::size_t k = 0; k < n; ++k) {
      // The pass may have spent milliseconds on replies, status and events
      // before it got here: pace on the time of each send, not of the pass.
      const TimePoint now = clock_.now();
      const std::size_t index = (rr_ + k) % n;
      if (!line_.allows(now)) {
        rr_ = index;  // this hand goes first when the line has room again
        return;
      }
      const std::uint8_t id = order_[index];
      if (id == 0 && !id_zero_.may_send(now)) continue;
      HandDriver& driver = *drivers_[id];
      const auto message = driver.next_frame(now);
      if (!message) continue;
      if (send_frame(driver, *message, now)) continue;
      rr_ = index;  // this hand goes first when the bus takes frames again
      return;
    }
    // Round robin: a different hand leads every pass, so none is always last.
    if (n > 0) rr_ = (rr_ + 1) % n;
    send_probes(clock_.now());
  }

  /// Sends one driver's frame; false if the bus took it not (the driver will
  /// offer it again) and the pass should send no more.
  bool send_frame(HandDriver& driver, const protocol::Message& message, TimePoint now) {
    const auto sent = bus_->send(to_frame(message));
    if (sent) {
      frame_left(driver, now);
      return true;
    }
    frame_refused(driver, message, sent.error(), now);
    return false;
  }

  /// Books a frame the bus took: the counters, the line budget, and the
  /// interval its hand (every hand, for ID 0) now waits.
  void frame_left(HandDriver& driver, TimePoint now) {
    const std::uint8_t id = driver.can_id();
    frames_sent_.fetch_add(1);
    recent_frames_.count(1);
    line_.used(now);
    // The interval counts from when the frame left, which is after now.
    const TimePoint left = clock_.now();
    // So does the wait for its reply: the loop thread, preempted between
    // taking `now` and the write, once re-sent a position write whose echo
    // was on its way (a loaded user-mode Linux, kernel.takeover_kills).
    driver.frame_left(left);
    driver.hold_sends_until(left + options_.frame_spacing());
    id_zero_.frame_sent(id, left);
    // A frame to ID 0 reached every hand: each waits the interval after it.
    if (id == 0) hold_others(left + options_.frame_spacing());
  }

  /// A frame the bus did not take: its driver offers it again later.
  void frame_refused(HandDriver& driver, const protocol::Message& message, bus::BusError error,
                     TimePoint now) {
    driver.unsend();
    if (error == bus::BusError::link_down) {
      on_link_change(link_.on_link_lost(), now);
      return;
    }
    if (error != bus::BusError::would_block) {
      bus_errors_.fetch_add(1);
      spdlog::warn("{}: could not send {}: {}", name_, protocol::describe(message),
                   bus::to_string(error));
    }
  }

  /// Group members whose group released them go first, back to back, past
  /// the line budget (a group is a burst its caller asked for; the budget
  /// still counts it, so the polls after it wait their share). One
  /// Bus::send_burst: on SocketCAN one system call, so nothing on this
  /// machine runs between a group's frames. False if the bus did not take
  /// them all: the pass sends nothing more.
  bool send_group_frames() {
    group_drivers_.clear();
    group_messages_.clear();
    group_frames_.clear();
    const TimePoint now = clock_.now();
    for (std::uint8_t id : order_) {
      HandDriver& driver = *drivers_[id];
      if (auto message = driver.next_group_frame(now)) {
        group_drivers_.push_back(&driver);
        group_messages_.push_back(*message);
        group_frames_.push_back(to_frame(*message));
      }
    }
    if (group_frames_.empty()) return true;
    const auto taken = bus_->send_burst(group_frames_);
    const std::size_t count = taken ? taken.value() : 0;
    for (std::size_t i = 0; i < count; ++i) frame_left(*group_drivers_[i], now);
    if (count == group_frames_.size()) return true;
    // Those after the first refused frame go back; the first says why, once
    // (a lost link is handled last, with every frame back with its driver).
    for (std::size_t i = count + 1; i < group_frames_.size(); ++i) group_drivers_[i]->unsend();
    const bus::BusError why = taken ? bus::BusError::would_block : taken.error();
    frame_refused(*group_drivers_[count], group_messages_[count], why, now);
    return false;
  }

  // ---- pacing across senders (id_zero_reservation.hpp) ---------------------

  void reserve_for_id_zero(TimePoint now) {
    HandDriver* id_zero = drivers_[0].get();
    const bool waiting = id_zero && id_zero->has_command_frame();
    const auto slot =
        id_zero_.reserve(waiting, waiting ? std::max(now, id_zero->paced_until()) : now);
    if (!slot) return;
    id_zero->hold_sends_until(*slot);
    hold_others(*slot + options_.frame_spacing());
  }

  /// Every hand but ID 0 sends nothing before `until`.
  void hold_others(TimePoint until) {
    for (std::uint8_t id : order_) {
      if (id != 0) drivers_[id]->hold_sends_until(until);
    }
  }

  // ---- discovery (discovery_scan.hpp) ----------------------------------------

  void send_probes(TimePoint now) {
    if (!scan_.active()) return;
    if (const TimePoint allowed = id_zero_.probes_allowed_at(); now < allowed) {
      scan_.hold_until(allowed);
      return;
    }
    while (line_.allows(now)) {
      const auto id = scan_.due_probe(now);
      if (!id) return;
      const auto sent =
          bus_->send(to_frame(protocol::make_read(*id, protocol::reg::kFirmwareVersion)));
      if (!sent) {
        if (sent.error() == bus::BusError::link_down) on_link_change(link_.on_link_lost(), now);
        if (sent.error() == bus::BusError::io_error) bus_errors_.fetch_add(1);
        return;  // would_block: the next pass tries this ID again
      }
      frames_sent_.fetch_add(1);
      recent_frames_.count(1);
      line_.used(now);
      const TimePoint left = clock_.now();
      id_zero_.probe_sent(left);
      if (!scan_.probe_sent(now, left)) return;
    }
  }

  void scan_on_time(TimePoint now) {
    const ScanTick tick = scan_.on_time(now, link_.up());
    if (tick == ScanTick::started) spdlog::debug("{}: probing CAN IDs 1-255 for hands", name_);
    if (tick == ScanTick::complete) finish_scan();
  }

  void finish_scan() {
    if (!scan_.active()) return;
    std::vector<std::uint8_t> found;
    for (std::uint8_t id : order_) {
      if (id != 0 && drivers_[id]->state().online) found.push_back(id);
    }
    std::sort(found.begin(), found.end());
    spdlog::debug("{}: scan found {} hands", name_, found.size());
    scan_.finish(found);
  }

  // ---- link (link_monitor.hpp) -------------------------------------------------

  void on_link_change(LinkChange change, TimePoint now) {
    if (change == LinkChange::went_down) {
      spdlog::warn("{}: bus down ({})", name_, bus_->spec());
      observer_.on_link(bus::LinkState::down);
      for (std::uint8_t id : order_) drivers_[id]->on_link_down(now);
      finish_scan();
    } else if (change == LinkChange::came_up) {
      spdlog::info("{}: bus up ({})", name_, bus_->spec());
      observer_.on_link(bus::LinkState::up);
      for (std::uint8_t id : order_) drivers_[id]->on_link_up(now);
      scan_.on_link_up(now);
    }
  }

  std::string name_;
  std::unique_ptr<bus::Bus> bus_;
  SchedulerOptions options_;
  const Clock& clock_;
  HandObserver& observer_;

  std::atomic<std::uint64_t> frames_sent_{0};
  std::atomic<std::uint64_t> frames_received_{0};
  std::atomic<std::uint64_t> unexpected_{0};
  std::atomic<std::uint64_t> bus_errors_{0};
  /// The set of hands and their published states (hand_roster.hpp).
  HandRoster roster_;
  BusLatencyCounters latency_;
  DriverContext context_;
  /// Per hand; created on first use (from any thread), never removed.
  std::array<std::atomic<HandCounters*>, 256> hand_counters_{};
  std::uint32_t bit_rate_ = 0;
  RecentFrames recent_frames_{clock_.now()};
  /// Its state is read by metrics() and link_state() on any thread.
  LinkMonitor link_;

  // Read by submit() on any thread; written by the loop.
  std::array<std::atomic<int>, 256> queued_{};

  std::mutex inbox_mutex_;
  std::vector<Submitted> inbox_;
  std::vector<ScanCompletion> scan_requests_;
  bool stopped_ = false;

  // Loop thread only.
  std::array<std::unique_ptr<HandDriver>, 256> drivers_{};
  std::vector<std::uint8_t> order_;
  // The group sweep's scratch, kept to spare the loop allocations.
  std::vector<HandDriver*> group_drivers_;
  std::vector<protocol::Message> group_messages_;
  std::vector<bus::CanFrame> group_frames_;
  std::size_t rr_ = 0;
  std::vector<bus::CanFrame> frames_;
  LineBudget line_;
  IdZeroReservation id_zero_;
  DiscoveryScan scan_;

  std::atomic<bool> running_{false};
  std::thread thread_;
};

BusScheduler::BusScheduler(std::string bus_name, std::unique_ptr<bus::Bus> bus,
                           std::vector<HandConfig> hands, SchedulerOptions options,
                           const Clock& clock, HandObserver& observer)
    : impl_(std::make_unique<Impl>(std::move(bus_name), std::move(bus), std::move(hands), options,
                                   clock, observer)) {}

BusScheduler::~BusScheduler() {
  impl_->stop();
}

void BusScheduler::submit(std::uint8_t can_id, Command command, Completion done) {
  impl_->submit(can_id, std::move(command), std::move(done));
}
void BusScheduler::request_scan(ScanCompletion done) {
  impl_->request_scan(std::move(done));
}
std::vector<HandState> BusScheduler::state() const {
  return impl_->state();
}
const HandRoster& BusScheduler::roster() const {
  return impl_->roster();
}
SchedulerCounters BusScheduler::counters() const {
  return impl_->counters();
}
BusMetrics BusScheduler::metrics() const {
  return impl_->metrics();
}
const std::string& BusScheduler::name() const {
  return impl_->name();
}
bus::LinkState BusScheduler::link_state() const {
  return impl_->link_state();
}
void BusScheduler::warm(const std::vector<HandState>& seen) {
  impl_->warm(seen);
}
void BusScheduler::start() {
  impl_->start();
}
void BusScheduler::stop() {
  impl_->stop();
}
void BusScheduler::step() {
  impl_->step();
}
TimePoint BusScheduler::next_wakeup() const {
  return impl_->next_wakeup();
}

}  // namespace dh3::hand
