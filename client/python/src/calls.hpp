#pragma once
// Calls into the client from Python: blocking ones that wait in slices,
// asynchronous ones that return a concurrent.futures.Future completed by the
// client's completion callback, and callbacks from the client's thread back
// into Python (see support.hpp for the GIL).

#include <functional>
#include <future>
#include <utility>

#include "dh3/client.hpp"
#include "dh3/group.hpp"
#include "support.hpp"

namespace dh3::python {

/// A concurrent.futures.Future, and the completion callback that sets its
/// result: on the client's callback thread, taking the GIL there (no thread of
/// its own). `R`: dh3::Reply or dh3::GroupReply.
template <typename R>
std::pair<py::object, std::function<void(R)>> python_future();

/// Waits (with the GIL released) until every Future made by python_future()
/// is complete, or `timeout` passed.
void wait_for_futures(Milliseconds timeout);

/// Starts a call with the GIL released.
template <typename Start>
auto start_call(Start&& start) {
  py::gil_scoped_release released;
  return start();
}

/// A blocking call: `start` returns the call's std::future, which the client
/// fulfils where the call ends, so waiting for it works on the client's
/// callback thread too (a Python callback may make blocking calls).
template <typename Start>
auto blocking_call(Start&& start) {
  auto future = start_call(std::forward<Start>(start));
  return wait_interruptibly(future);
}

/// An asynchronous call: `start(callback)` starts it with the completion
/// callback; returns the Future that callback completes.
template <typename R, typename Start>
py::object async_call(Start&& start) {
  auto [future, callback] = python_future<R>();
  start_call([&] {
    start(std::move(callback));
    return 0;
  });
  return future;
}

/// `callback` as the client calls it: on the client's thread, which takes the
/// GIL to run it and reports what it raises as unraisable (`what`).
template <typename Arg>
std::function<void(const Arg&)> python_callback(py::function callback, const char* what) {
  auto target = share(std::move(callback));
  return [target, what](const Arg& argument) {
    if (!Py_IsInitialized()) return;
    py::gil_scoped_acquire gil;
    try {
      (*target)(argument);
    } catch (py::error_already_set& error) {
      // The client's thread has nobody to raise to: report like Python does
      // for exceptions in __del__ and carry on with the next callback.
      error.discard_as_unraisable(what);
    }
  };
}

/// A Subscription whose unsubscribe (which waits for a running callback to
/// end) releases the GIL: the callback may be waiting for it.
class PySubscription {
 public:
  explicit PySubscription(dh3::Subscription subscription)
      : subscription_(std::move(subscription)) {}
  ~PySubscription() { unsubscribe(); }
  PySubscription(const PySubscription&) = delete;
  PySubscription& operator=(const PySubscription&) = delete;

  void unsubscribe();
  [[nodiscard]] bool active() const { return subscription_.active(); }

 private:
  dh3::Subscription subscription_;
};

}  // namespace dh3::python
