// Dispatcher: the one thread that runs user callbacks, in order.

#include "dispatcher.hpp"

#include <algorithm>

namespace dh3::detail {

Dispatcher::Dispatcher() : state_(std::make_shared<State>()) {
  thread_ = std::thread([state = state_] {
    std::unique_lock lock(state->mutex);
    for (;;) {
      state->wake.wait(lock, [&] { return state->stop || !state->tasks.empty(); });
      if (state->tasks.empty()) return;  // stopped, and nothing left that must run
      auto task = std::move(state->tasks.front());
      state->tasks.pop_front();
      if (state->stop && !task.must_run) continue;
      lock.unlock();
      task.run();
      lock.lock();
    }
  });
  thread_id_ = thread_.get_id();
}

Dispatcher::~Dispatcher() {
  stop();
}

void Dispatcher::post(std::function<void()> task) {
  push(std::move(task), false);
}

void Dispatcher::post_must_run(std::function<void()> task) {
  push(std::move(task), true);
}

void Dispatcher::push(std::function<void()> task, bool must_run) {
  {
    std::lock_guard lock(state_->mutex);
    if (!state_->stop) {
      state_->tasks.push_back(State::Task{std::move(task), must_run});
      state_->wake.notify_one();
      return;
    }
  }
  if (must_run) task();
}

void Dispatcher::stop() {
  {
    std::lock_guard lock(state_->mutex);
    state_->stop = true;
    auto& tasks = state_->tasks;
    tasks.erase(std::remove_if(tasks.begin(), tasks.end(),
                               [](const State::Task& task) { return !task.must_run; }),
                tasks.end());
  }
  state_->wake.notify_all();
  if (!thread_.joinable()) return;
  if (on_dispatcher_thread()) {
    thread_.detach();  // the task running now returns into a loop that ends
  } else {
    thread_.join();
  }
}

bool Dispatcher::on_dispatcher_thread() const {
  return std::this_thread::get_id() == thread_id_;
}

}  // namespace dh3::detail
