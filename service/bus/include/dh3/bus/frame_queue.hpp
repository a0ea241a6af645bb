#pragma once
// The flight recorder's hand-over from a bus loop to its writer thread: a
// bounded lock-free queue for one producer (the bus loop) and one consumer
// (the writer). push() never waits and never allocates; when the writer has
// fallen behind and the queue is full, the frame is dropped and counted, so
// recording can never hold up the bus.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dh3/bus/candump_log.hpp"

namespace dh3::bus {

class FrameQueue {
 public:
  /// Holds at least `capacity` frames (rounded up to a power of two, at least 2).
  explicit FrameQueue(std::size_t capacity);
  FrameQueue(const FrameQueue&) = delete;
  FrameQueue& operator=(const FrameQueue&) = delete;

  /// Producer only. False, and the frame counted as dropped, when full.
  bool push(const LoggedFrame& frame);
  /// Consumer only. Appends up to `max` frames, oldest first; how many.
  std::size_t pop(std::vector<LoggedFrame>& out, std::size_t max);

  /// Any thread.
  [[nodiscard]] std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::size_t capacity() const { return slots_.size(); }

 private:
  std::vector<LoggedFrame> slots_;
  std::size_t mask_ = 0;
  // Each index only grows; its owner writes it, the other side reads it.
  alignas(64) std::atomic<std::size_t> head_{0};  ///< next to pop (consumer)
  alignas(64) std::atomic<std::size_t> tail_{0};  ///< next to fill (producer)
  alignas(64) std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace dh3::bus
