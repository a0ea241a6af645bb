#include "dh3/app/standby_watch.hpp"

#include <spdlog/spdlog.h>

namespace dh3::app {
namespace {

/// How long one receive waits: the loop checks for its end this often, and a
/// silent bus is read this often (silent_at()), which bounds how long a
/// lapse waits for the buses' word.
constexpr Duration kReceiveWait = std::chrono::milliseconds(20);

std::unique_ptr<bus::Bus> gated(std::unique_ptr<bus::Bus> opened) {
  return std::make_unique<bus::StandbyBus>(std::move(opened));
}

}  // namespace

StandbyWatch::Watched::Watched(dds::BusSetup opened, Duration quiet, TimePoint now)
    : setup(std::move(opened)),
      hands(setup.hands, setup.scheduler.reply_timeout),
      fence(quiet, now) {
  setup.bus = gated(std::move(setup.bus));
  gate = static_cast<bus::StandbyBus*>(setup.bus.get());
}

StandbyWatch::StandbyWatch(std::vector<dds::BusSetup> buses, Duration quiet, const Clock& clock)
    : clock_(clock) {
  for (dds::BusSetup& setup : buses) {
    buses_.push_back(std::make_unique<Watched>(std::move(setup), quiet, clock.now()));
  }
}

StandbyWatch::~StandbyWatch() {
  running_.store(false);
  for (const auto& watched : buses_) {
    if (watched->gate) watched->gate->wake();
    if (watched->loop.joinable()) watched->loop.join();
  }
}

void StandbyWatch::start() {
  running_.store(true);
  for (const auto& watched : buses_) {
    watched->loop = std::thread([this, &w = *watched] { watch(w); });
  }
}

void StandbyWatch::watch(Watched& watched) {
  std::vector<bus::CanFrame> frames;
  bool link_reported_down = false;
  while (running_.load()) {
    frames.clear();
    const auto received = watched.setup.bus->receive(frames, kReceiveWait);
    const bool down = !received && received.error() == bus::BusError::link_down;
    if (down != link_reported_down) {
      link_reported_down = down;
      if (down) {
        spdlog::warn("standby: bus '{}' is down: its hands are not watched", watched.setup.name);
      } else {
        spdlog::info("standby: bus '{}' is up again", watched.setup.name);
      }
    }
    const TimePoint now = clock_.now();
    const std::lock_guard lock(watched.mutex);
    if (frames.empty()) {
      const bool silent = received && watched.hands.requests_seen() > 0 && watched.fence.clear(now);
      watched.silent_read_at = silent ? std::optional(now) : std::nullopt;
      continue;
    }
    for (const bus::CanFrame& frame : frames) {
      if (watched.hands.on_frame(frame, now) == hand::FrameRole::request) {
        watched.fence.on_request(now);
        watched.silent_read_at.reset();
      }
    }
  }
}

std::vector<dds::BusSetup> StandbyWatch::take_buses() {
  running_.store(false);
  std::vector<dds::BusSetup> setups;
  for (const auto& watched : buses_) {
    watched->gate->wake();
    if (watched->loop.joinable()) watched->loop.join();
  }
  for (const auto& watched : buses_) {
    if (!watched->gate) continue;
    watched->gate->promote();
    watched->gate = nullptr;
    setups.push_back(std::move(watched->setup));
  }
  return setups;
}

std::vector<std::vector<hand::HandState>> StandbyWatch::states() const {
  std::vector<std::vector<hand::HandState>> out;
  for (const auto& watched : buses_) {
    const std::lock_guard lock(watched->mutex);
    out.push_back(watched->hands.states());
  }
  return out;
}

bool StandbyWatch::fences_clear(TimePoint now) const {
  return busy_buses(now).empty();
}

std::optional<TimePoint> StandbyWatch::silent_at() const {
  std::optional<TimePoint> earliest;
  for (const auto& watched : buses_) {
    const std::lock_guard lock(watched->mutex);
    if (!watched->silent_read_at) return std::nullopt;
    if (!earliest || *watched->silent_read_at < *earliest) earliest = watched->silent_read_at;
  }
  return earliest;
}

std::vector<std::string> StandbyWatch::busy_buses(TimePoint now) const {
  std::vector<std::string> busy;
  for (const auto& watched : buses_) {
    const std::lock_guard lock(watched->mutex);
    if (!watched->fence.clear(now)) busy.push_back(watched->setup.name);
  }
  return busy;
}

std::uint64_t StandbyWatch::requests_seen() const {
  std::uint64_t total = 0;
  for (const auto& watched : buses_) {
    const std::lock_guard lock(watched->mutex);
    total += watched->hands.requests_seen();
  }
  return total;
}

}  // namespace dh3::app
