#pragma once
// The thread that runs user callbacks (events, statuses, calls' completions)
// in order, so user code never runs on a DDS thread.

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

  /// A task that stop() may drop (an event or status: news nobody waits for).
  void post(std::function<void()> task);
  /// A task that runs whatever happens (a call's completion): queued, it runs
  /// before the thread ends; posted once stopped, it runs at once, here.
  void post_must_run(std::function<void()> task);
  /// Drops the droppable tasks queued, runs the others, and ends the thread
  /// (joined, or detached when called from a task).
  void stop();
  [[nodiscard]] bool on_dispatcher_thread() const;

 private:
  struct State {
    std::mutex mutex;
    std::condition_variable wake;
    struct Task {
      std::function<void()> run;
      bool must_run = false;
    };
    std::deque<Task> tasks;
    bool stop = false;
  };
  std::shared_ptr<State> state_;
  void push(std::function<void()> task, bool must_run);

  std::thread thread_;
  std::thread::id thread_id_;
};

}  // namespace dh3::detail
