#include "dh3/bus/frame_queue.hpp"

#include <algorithm>
#include <bit>

namespace dh3::bus {

FrameQueue::FrameQueue(std::size_t capacity)
    : slots_(std::bit_ceil(std::max<std::size_t>(capacity, 2))), mask_(slots_.size() - 1) {}

bool FrameQueue::push(const LoggedFrame& frame) {
  const std::size_t tail = tail_.load(std::memory_order_relaxed);
  if (tail - head_.load(std::memory_order_acquire) >= slots_.size()) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  slots_[tail & mask_] = frame;
  tail_.store(tail + 1, std::memory_order_release);  // publishes the slot
  return true;
}

std::size_t FrameQueue::pop(std::vector<LoggedFrame>& out, std::size_t max) {
  const std::size_t head = head_.load(std::memory_order_relaxed);
  const std::size_t available = tail_.load(std::memory_order_acquire) - head;
  const std::size_t count = std::min(available, max);
  for (std::size_t i = 0; i < count; ++i) out.push_back(slots_[(head + i) & mask_]);
  head_.store(head + count, std::memory_order_release);  // frees the slots
  return count;
}

}  // namespace dh3::bus
