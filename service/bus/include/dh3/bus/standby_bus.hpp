#pragma once
// A bus held by a standby service: it receives every frame its backend
// receives, and sends nothing until promote(). The gate sits here, at the
// bus, so that no layer above (a poller, a discovery scan, a command that
// slipped through) can put a frame on a line another service drives: two
// masters on a DH-3 bus would complete on each other's echoes, since request
// and echo share the CAN ID and the data.
//
// What the backend must offer for observing: SocketCAN delivers every frame
// on the interface to every raw socket (vcan does so too; a second PC needs
// its own adapter on the same wire); dh3-sim's transfer box sends every frame
// to every client when started with --shared; a real transfer box that takes
// one client at a time is not observed (docs/hot-standby.md).
//
// Threading: as Bus; promote() and promoted() from any thread.

#include <atomic>
#include <memory>

#include "dh3/bus/bus.hpp"

namespace dh3::bus {

class StandbyBus final : public Bus {
 public:
  explicit StandbyBus(std::unique_ptr<Bus> inner);

  [[nodiscard]] const std::string& spec() const override { return inner_->spec(); }
  /// not_permitted until promote(); then the backend's.
  Result<void, BusError> send(const CanFrame& frame) override;
  Result<std::size_t, BusError> send_burst(std::span<const CanFrame> frames) override;
  Result<void, BusError> receive(std::vector<CanFrame>& out, Duration timeout) override {
    return inner_->receive(out, timeout);
  }
  [[nodiscard]] std::span<const WallTime> receive_times() const override {
    return inner_->receive_times();
  }
  void wake() override { inner_->wake(); }
  [[nodiscard]] LinkState link_state() const override { return inner_->link_state(); }
  [[nodiscard]] std::uint32_t bit_rate() const override { return inner_->bit_rate(); }
  [[nodiscard]] BusDiagnostics diagnostics() const override { return inner_->diagnostics(); }

  /// Opens the gate: from now on frames go to the backend. Irreversible: a
  /// service that took over stays the active one until it stops.
  void promote() { promoted_.store(true, std::memory_order_release); }
  [[nodiscard]] bool promoted() const { return promoted_.load(std::memory_order_acquire); }
  /// Frames refused while not promoted.
  [[nodiscard]] std::uint64_t refused() const { return refused_.load(std::memory_order_relaxed); }

 private:
  std::unique_ptr<Bus> inner_;
  std::atomic<bool> promoted_{false};
  std::atomic<std::uint64_t> refused_{0};
};

}  // namespace dh3::bus
