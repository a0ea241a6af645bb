// Dispatcher: the one thread that runs user callbacks, in order.

#include "dispatcher.hpp"

namespace dh3::detail {

Dispatcher::Dispatcher() : state_(std::make_shared<State>()) {
  thread_ = std::thread([state = state_] {
    std::unique_lock lock(state->mutex);
    for (;;) {
      state->wake.wait(lock, [&] { return state->stop || !state->tasks.empty(); });
      if (state->stop) return;
      auto task = std::move(state->tasks.front());
      state->tasks.pop_front();
      lock.unlock();
      task();
      lock.lock();
    }
  });
  thread_id_ = thread_.get_id();
}

Dispatcher::~Dispatcher() {
  stop();
}

void Dispatcher::post(std::function<void()> task) {
  {
    std::lock_guard lock(state_->mutex);
    if (state_->stop) return;
    state_->tasks.push_back(std::move(task));
  }
  state_->wake.notify_one();
}

void Dispatcher::stop() {
  {
    std::lock_guard lock(state_->mutex);
    state_->stop = true;
    state_->tasks.clear();
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
