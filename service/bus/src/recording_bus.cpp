#include "dh3/bus/recording_bus.hpp"

namespace dh3::bus {

RecordingBus::RecordingBus(std::unique_ptr<Bus> inner, std::unique_ptr<FrameRecorder> recorder)
    : inner_(std::move(inner)), recorder_(std::move(recorder)) {}

Result<void, BusError> RecordingBus::send(const CanFrame& frame) {
  auto sent = inner_->send(frame);
  if (sent) recorder_->record(FrameDirection::sent, frame, std::chrono::system_clock::now());
  return sent;
}

Result<std::size_t, BusError> RecordingBus::send_burst(std::span<const CanFrame> frames) {
  auto taken = inner_->send_burst(frames);
  if (!taken) return taken;
  const WallTime sent_at = std::chrono::system_clock::now();
  for (std::size_t i = 0; i < taken.value(); ++i) {
    recorder_->record(FrameDirection::sent, frames[i], sent_at);
  }
  return taken;
}

Result<void, BusError> RecordingBus::receive(std::vector<CanFrame>& out, Duration timeout) {
  const std::size_t before = out.size();
  auto received = inner_->receive(out, timeout);
  if (out.size() == before) return received;
  const std::span<const WallTime> times = inner_->receive_times();
  const WallTime read_at = std::chrono::system_clock::now();
  for (std::size_t i = before; i < out.size(); ++i) {
    const std::size_t index = i - before;
    recorder_->record(FrameDirection::received, out[i],
                      index < times.size() ? times[index] : read_at);
  }
  return received;
}

BusDiagnostics RecordingBus::diagnostics() const {
  BusDiagnostics out = inner_->diagnostics();
  out.recorder = recorder_->figures();
  return out;
}

}  // namespace dh3::bus
