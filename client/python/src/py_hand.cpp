#include "py_hand.hpp"

#include <algorithm>

namespace dh3::python {

namespace {

bool is_newer(const dh3::HandStatus& s, const dh3::HandStatus& old) {
  return s.update_seq != old.update_seq || s.timestamp_ns != old.timestamp_ns ||
         s.read_at_ns != old.read_at_ns || s.online != old.online ||
         s.service_lost != old.service_lost;
}

}  // namespace

std::optional<dh3::HandStatus> PyHand::status() const {
  py::gil_scoped_release released;
  return hand_.status();
}

std::optional<dh3::HandStatus> PyHand::wait_until(const py::function& predicate,
                                                  const OptionalSeconds& timeout) const {
  const auto deadline = Clock::now() + effective(timeout);
  std::optional<dh3::HandStatus> seen = status();
  for (;;) {
    if (seen && py::cast<bool>(predicate(*seen))) return seen;
    auto next = next_status(seen, deadline);
    if (!next) return std::nullopt;
    seen = std::move(next);
  }
}

std::optional<dh3::HandStatus> PyHand::next_status(const std::optional<dh3::HandStatus>& seen,
                                                   Clock::time_point deadline) const {
  for (;;) {
    const auto left = std::chrono::duration_cast<Milliseconds>(deadline - Clock::now());
    if (left <= Milliseconds::zero()) return std::nullopt;
    std::optional<dh3::HandStatus> next;
    {
      py::gil_scoped_release released;
      next = hand_.wait_until(
          [&seen](const dh3::HandStatus& s) { return !seen || is_newer(s, *seen); },
          std::clamp(left, Milliseconds(1), kSlice));
    }
    if (next) return next;
    check_signals();
  }
}

}  // namespace dh3::python
