#pragma once
// What a test's callbacks heard, in the order they ran and on which thread;
// the test waits until enough came (20 s only guard against a failure: it
// never waits for a time).

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace dh3::test {

class Heard {
 public:
  void add(std::string what) {
    {
      std::lock_guard lock(mutex_);
      items_.push_back(std::move(what));
      threads_.push_back(std::this_thread::get_id());
    }
    changed_.notify_all();
  }
  /// What was heard once `count` items were, or at the deadline.
  std::vector<std::string> wait_for(std::size_t count) {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, std::chrono::seconds(20), [&] { return items_.size() >= count; });
    return items_;
  }
  std::vector<std::string> items() {
    std::lock_guard lock(mutex_);
    return items_;
  }
  std::vector<std::thread::id> threads() {
    std::lock_guard lock(mutex_);
    return threads_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::string> items_;
  std::vector<std::thread::id> threads_;
};

}  // namespace dh3::test
