#pragma once
// dh3.Client's C++ side: a dh3::Client that can be closed while calls are in
// progress, and waits that end on Ctrl-C and on close().

#include <algorithm>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "dh3/client.hpp"
#include "py_hand.hpp"
#include "support.hpp"

namespace dh3::python {

/// The C++ client, shared by the calls in progress; destroyed without the GIL
/// (~Client waits for the callback thread, which may be waiting for the GIL).
using ClientPtr = std::shared_ptr<dh3::Client>;

/// A message of a wait of `slice` that speaks of `whole` instead.
std::string widen_duration(std::string message, Milliseconds slice, Milliseconds whole);

class PyClient {
 public:
  explicit PyClient(dh3::ClientOptions options);
  ~PyClient();
  PyClient(const PyClient&) = delete;
  PyClient& operator=(const PyClient&) = delete;

  /// Leaves the domain: pending calls end NOT_CONNECTED, callbacks stop, and
  /// Hands of this client answer NOT_CONNECTED from now on. (A call another
  /// thread is starting at this moment finishes first.)
  void close();

  /// The client, or dh3.Error(NOT_CONNECTED) once closed. The GIL must be held.
  ClientPtr client();
  /// The client, or null once closed.
  ClientPtr current();

  [[nodiscard]] Milliseconds effective(const OptionalSeconds& timeout);

  PyHand wrap(dh3::Hand hand) { return PyHand(std::move(hand), client()->default_timeout()); }

  /// Client::wait_for_statuses in slices; close() ends it.
  bool wait_for_statuses(const OptionalSeconds& timeout);
  /// Client::find_hand with the GIL released; dh3.Error if there is none.
  PyHand find_hand(const std::string& spec);

  /// Repeats a waiting lookup in slices until it succeeds, fails for good
  /// (INVALID_ARGUMENT) or the deadline passes; the last answer. The client is
  /// taken anew for each slice, so close() ends the wait (NOT_CONNECTED).
  template <typename T, typename Lookup>
  dh3::Found<T> wait_in_slices(const OptionalSeconds& timeout, Lookup&& lookup) {
    const auto whole = effective(timeout);
    const auto deadline = Clock::now() + whole;
    for (;;) {
      const auto left = std::chrono::duration_cast<Milliseconds>(deadline - Clock::now());
      const auto slice = std::clamp(left, Milliseconds(1), kSlice);
      auto current = client();
      std::optional<dh3::Found<T>> found;
      const auto asked = Clock::now();
      {
        py::gil_scoped_release released;
        found.emplace(lookup(*current, slice));
        current.reset();
      }
      // A lookup that ends before its slice has its answer: found, or refused
      // for good (a bad spec, a hand the service's own list rules out).
      if (*found || found->code() == dh3::Code::invalid_argument || Clock::now() - asked < slice) {
        return std::move(*found);
      }
      if (left <= kSlice) {
        // The message names the last slice's wait; the caller waited `whole`.
        return {found->code(), widen_duration(found->message(), slice, whole)};
      }
      check_signals();
    }
  }

 private:
  std::mutex mutex_;
  ClientPtr client_;
};

/// Closes every client not yet destroyed (interpreter exit).
void close_every_client();

}  // namespace dh3::python
