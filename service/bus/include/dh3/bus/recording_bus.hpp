#pragma once
// A bus with a flight recorder: wraps any backend and hands every frame it
// sends (when the backend took it) and receives to a FrameRecorder, which never
// blocks. A received frame carries the backend's receive time (the kernel's
// timestamp on SocketCAN, Bus::receive_times()), else the wall clock's when it
// was read; a sent frame the wall clock's when send() returned. A transfer
// box's frames are recorded as the CAN frames they carry.

#include <memory>

#include "dh3/bus/bus.hpp"
#include "dh3/bus/frame_recorder.hpp"

namespace dh3::bus {

class RecordingBus final : public Bus {
 public:
  RecordingBus(std::unique_ptr<Bus> inner, std::unique_ptr<FrameRecorder> recorder);

  [[nodiscard]] const std::string& spec() const override { return inner_->spec(); }
  Result<void, BusError> send(const CanFrame& frame) override;
  /// The backend's own burst; the frames it took are recorded.
  Result<std::size_t, BusError> send_burst(std::span<const CanFrame> frames) override;
  Result<void, BusError> receive(std::vector<CanFrame>& out, Duration timeout) override;
  [[nodiscard]] std::span<const WallTime> receive_times() const override {
    return inner_->receive_times();
  }
  void wake() override { inner_->wake(); }
  [[nodiscard]] LinkState link_state() const override { return inner_->link_state(); }
  [[nodiscard]] std::uint32_t bit_rate() const override { return inner_->bit_rate(); }
  /// The backend's, with the recorder's figures.
  [[nodiscard]] BusDiagnostics diagnostics() const override;

  [[nodiscard]] const FrameRecorder& recorder() const { return *recorder_; }

 private:
  std::unique_ptr<Bus> inner_;
  std::unique_ptr<FrameRecorder> recorder_;
};

}  // namespace dh3::bus
