#include "calls.hpp"

#include <condition_variable>
#include <mutex>
#include <thread>

namespace dh3::python {

namespace {

// Threads completing Futures are counted so that interpreter exit (dh3's
// atexit hook) can wait for them after closing the clients.
std::mutex g_in_flight_mutex;
std::condition_variable g_in_flight_done;
int g_in_flight = 0;

}  // namespace

py::object to_python_future(std::future<dh3::Reply> reply) {
  py::object future = py::module_::import("concurrent.futures").attr("Future")();
  future.attr("set_running_or_notify_cancel")();
  auto target = share(future);
  {
    std::lock_guard lock(g_in_flight_mutex);
    ++g_in_flight;
  }
  std::thread([reply = std::move(reply), target = std::move(target)]() mutable {
    dh3::Reply result = reply.get();
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
  }).detach();
  return future;
}

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
