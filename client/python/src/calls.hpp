#pragma once
// Calls into the client from Python: blocking ones that wait in slices,
// asynchronous ones that return a concurrent.futures.Future, and callbacks
// from the client's thread back into Python (see support.hpp for the GIL).

#include <functional>
#include <future>
#include <utility>

#include "dh3/client.hpp"
#include "support.hpp"

namespace dh3::python {

/// A concurrent.futures.Future completed with the Reply of `reply` by a thread
/// of its own.
py::object to_python_future(std::future<dh3::Reply> reply);

/// Waits (with the GIL released) until every thread completing a Future ended,
/// or `timeout` passed.
void wait_for_futures(Milliseconds timeout);

/// Starts a call with the GIL released.
template <typename Start>
std::future<dh3::Reply> start_call(Start&& start) {
  py::gil_scoped_release released;
  return start();
}

template <typename Start>
dh3::Reply blocking_call(Start&& start) {
  auto future = start_call(std::forward<Start>(start));
  return wait_interruptibly(future);
}

template <typename Start>
py::object async_call(Start&& start) {
  return to_python_future(start_call(std::forward<Start>(start)));
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
