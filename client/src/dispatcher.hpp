#pragma once
// The thread that runs user callbacks (events, statuses) in order, so user
// code never runs on a DDS thread.

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>

namespace dh3::detail {

/// Runs tasks on one thread in the order posted. Its state is shared with the
/// thread, so the dispatcher may be stopped from one of its own tasks.
class Dispatcher {
 public:
  Dispatcher();
  ~Dispatcher();
  Dispatcher(const Dispatcher&) = delete;
  Dispatcher& operator=(const Dispatcher&) = delete;

  void post(std::function<void()> task);
  /// Drops what is queued and ends the thread (joined, or detached when
  /// called from a task).
  void stop();
  [[nodiscard]] bool on_dispatcher_thread() const;

 private:
  struct State {
    std::mutex mutex;
    std::condition_variable wake;
    std::deque<std::function<void()>> tasks;
    bool stop = false;
  };
  std::shared_ptr<State> state_;
  std::thread thread_;
  std::thread::id thread_id_;
};

}  // namespace dh3::detail
