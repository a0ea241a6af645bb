#include "calls.hpp"

#include <condition_variable>
#include <mutex>

namespace dh3::python {

namespace {

// Futures not yet complete are counted so that interpreter exit (dh3's
// atexit hook) can wait for them after closing the clients.
std::mutex g_in_flight_mutex;
std::condition_variable g_in_flight_done;
int g_in_flight = 0;

}  // namespace

template <typename R>
std::pair<py::object, std::function<void(R)>> python_future() {
  py::object future = py::module_::import("concurrent.futures").attr("Future")();
  future.attr("set_running_or_notify_cancel")();
  {
    std::lock_guard lock(g_in_flight_mutex);
    ++g_in_flight;
  }
  auto complete = [target = share(future)](R result) mutable {
    if (Py_IsInitialized()) {
      py::gil_scoped_acquire gil;
      try {
        target->attr("set_result")(py::cast(std::move(result)));
      } catch (py::error_already_set& error) {
        error.discard_as_unraisable("dh3: completing a Future");
      }
      target.reset();
    }
    std::lock_guard lock(g_in_flight_mutex);
    --g_in_flight;
    g_in_flight_done.notify_all();
  };
  return {std::move(future), std::move(complete)};
}

template std::pair<py::object, std::function<void(dh3::Reply)>> python_future<dh3::Reply>();
template std::pair<py::object, std::function<void(dh3::GroupReply)>>
python_future<dh3::GroupReply>();

void wait_for_futures(Milliseconds timeout) {
  py::gil_scoped_release released;
  std::unique_lock lock(g_in_flight_mutex);
  g_in_flight_done.wait_for(lock, timeout, [] { return g_in_flight == 0; });
}

void PySubscription::unsubscribe() {
  if (!Py_IsInitialized() || !PyGILState_Check()) {
    subscription_.unsubscribe();
    return;
  }
  py::gil_scoped_release released;
  subscription_.unsubscribe();
}

}  // namespace dh3::python
