#pragma once
// Waiting on a real Bus in tests: call receive() in short slices until a
// condition holds or a generous deadline passes (never a fixed sleep).

#include <chrono>
#include <functional>
#include <vector>

#include "dh3/bus/bus.hpp"
#include "dh3/protocol/codec.hpp"

namespace dh3::test {

inline constexpr auto kBusDeadline = std::chrono::seconds(10);
inline constexpr auto kBusSlice = std::chrono::milliseconds(20);

/// Receives until `done(frames so far)` is true or the deadline passes;
/// returns every frame received. Link errors are tolerated (the link may be
/// coming up); `last_error` receives the last one if given.
inline std::vector<bus::CanFrame> receive_until(
    bus::Bus& bus, const std::function<bool(const std::vector<bus::CanFrame>&)>& done,
    std::chrono::steady_clock::duration deadline = kBusDeadline) {
  std::vector<bus::CanFrame> frames;
  const auto until = std::chrono::steady_clock::now() + deadline;
  while (!done(frames) && std::chrono::steady_clock::now() < until) {
    (void)bus.receive(frames, kBusSlice);
  }
  return frames;
}

/// Receives until at least `count` frames arrived (or the deadline passed).
inline std::vector<bus::CanFrame> receive_frames(
    bus::Bus& bus, std::size_t count, std::chrono::steady_clock::duration deadline = kBusDeadline) {
  return receive_until(
      bus, [count](const std::vector<bus::CanFrame>& f) { return f.size() >= count; }, deadline);
}

/// Calls receive() until the bus reports `state`; true if it did in time.
/// Frames received meanwhile are appended to `frames` if given.
inline bool wait_for_link(bus::Bus& bus, bus::LinkState state,
                          std::vector<bus::CanFrame>* frames = nullptr,
                          std::chrono::steady_clock::duration deadline = kBusDeadline) {
  std::vector<bus::CanFrame> scratch;
  auto& out = frames != nullptr ? *frames : scratch;
  const auto until = std::chrono::steady_clock::now() + deadline;
  while (bus.link_state() != state && std::chrono::steady_clock::now() < until) {
    (void)bus.receive(out, kBusSlice);
  }
  return bus.link_state() == state;
}

/// The CAN frame that carries `message`.
inline bus::CanFrame to_can_frame(const protocol::Message& message) {
  bus::CanFrame frame;
  frame.id = message.hand_id;
  frame.length = 8;
  frame.data = protocol::encode_payload(message);
  return frame;
}

}  // namespace dh3::test
