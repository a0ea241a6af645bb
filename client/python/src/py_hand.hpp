#pragma once
// dh3.Hand's C++ side: a dh3::Hand with what waiting in slices needs (the
// client's default timeout).

#include <optional>
#include <utility>

#include "dh3/client.hpp"
#include "support.hpp"

namespace dh3::python {

class PyHand {
 public:
  PyHand(dh3::Hand hand, Milliseconds default_timeout)
      : hand_(std::move(hand)), default_timeout_(default_timeout) {}

  dh3::Hand& hand() { return hand_; }
  [[nodiscard]] Milliseconds effective(const OptionalSeconds& timeout) const {
    return timeout ? to_milliseconds(*timeout, "timeout") : default_timeout_;
  }

  std::optional<dh3::HandStatus> status() const;

  /// Waits until `predicate(status)` is true. The C++ wait only tells that a
  /// new status arrived (no Python runs under the client's lock); the
  /// predicate runs here, with the GIL held.
  std::optional<dh3::HandStatus> wait_until(const py::function& predicate,
                                            const OptionalSeconds& timeout) const;

 private:
  /// The next status after `seen` (any status if none), or nullopt once
  /// `deadline` passed; checks for signals between slices.
  std::optional<dh3::HandStatus> next_status(const std::optional<dh3::HandStatus>& seen,
                                             Clock::time_point deadline) const;

  dh3::Hand hand_;
  Milliseconds default_timeout_;
};

}  // namespace dh3::python
