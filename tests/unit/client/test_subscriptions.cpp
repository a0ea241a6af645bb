// Subscriptions without DDS: callbacks run on the dispatcher thread, in the
// order posted, only for the hands asked for; the statuses known when a status
// subscription starts come first; a removed subscription hears nothing more;
// a throwing callback does not stop the others.

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "heard.hpp"
#include "subscriptions.hpp"

namespace dh3::detail {
namespace {

const HandAddress kLeft{"svc", "can0", 1};
const HandAddress kRight{"svc", "can0", 2};

using test::Heard;

HandStatus status_of(const HandAddress& address, std::uint64_t update_seq) {
  HandStatus status;
  status.address = address;
  status.update_seq = update_seq;
  return status;
}

/// "2#7": hand 2's update 7. Appended piece by piece: GCC 12 warns falsely
/// (-Wrestrict) on a chain of string operator+ at -O3.
std::string name_of(const HandStatus& status) {
  std::string name = std::to_string(status.address.can_id);
  name += '#';
  name += std::to_string(status.update_seq);
  return name;
}

std::string tagged(const char* tag, const std::string& message) {
  std::string out = tag;
  out += message;
  return out;
}

HandEvent event_saying(std::string message) {
  HandEvent event;
  event.hand = kLeft;
  event.message = std::move(message);
  return event;
}

std::shared_ptr<SubscriptionState> status_sub(Heard& heard, std::optional<HandAddress> only) {
  auto state = std::make_shared<SubscriptionState>();
  state->on_status = [&heard](const HandStatus& status) { heard.add(name_of(status)); };
  state->only = std::move(only);
  return state;
}

TEST(Subscriptions, StatusesGoInOrderToTheSubscriptionsOfTheirHandOnTheDispatcher) {
  Subscriptions subs;
  Heard all;
  Heard right;
  subs.add_status(status_sub(all, std::nullopt), {});
  subs.add_status(status_sub(right, kRight), {});
  subs.post_status(status_of(kLeft, 1));
  subs.post_status(status_of(kRight, 1));
  subs.post_status(status_of(kLeft, 2));
  EXPECT_EQ(all.wait_for(3), (std::vector<std::string>{"1#1", "2#1", "1#2"}));
  EXPECT_EQ(right.wait_for(1), (std::vector<std::string>{"2#1"}));
  for (const auto id : all.threads()) EXPECT_NE(id, std::this_thread::get_id());
  subs.stop();
}

TEST(Subscriptions, TheKnownStatusesComeBeforeLaterOnes) {
  Subscriptions subs;
  Heard heard;
  subs.add_status(status_sub(heard, std::nullopt), {status_of(kLeft, 4), status_of(kRight, 7)});
  subs.post_status(status_of(kLeft, 5));
  EXPECT_EQ(heard.wait_for(3), (std::vector<std::string>{"1#4", "2#7", "1#5"}));
  subs.stop();
}

TEST(Subscriptions, ARemovedSubscriptionHearsNothingMore) {
  Subscriptions subs;
  Heard removed;
  Heard kept;
  auto gone = status_sub(removed, std::nullopt);
  subs.add_status(gone, {});
  subs.add_status(status_sub(kept, std::nullopt), {});
  subs.post_status(status_of(kLeft, 1));
  ASSERT_EQ(removed.wait_for(1).size(), 1U);
  subs.remove(gone);
  EXPECT_FALSE(gone->active);
  subs.post_status(status_of(kLeft, 2));
  // Both were posted in one task each, the removed one first: once `kept` has
  // the second, the removed one would have had it too.
  EXPECT_EQ(kept.wait_for(2).size(), 2U);
  EXPECT_EQ(removed.wait_for(1), (std::vector<std::string>{"1#1"}));
  subs.stop();
}

TEST(Subscriptions, ACallbackMayUnsubscribeItselfAndAThrowingOneStopsNoOther) {
  Subscriptions subs;
  Heard heard;
  auto self = std::make_shared<SubscriptionState>();
  auto thrower = std::make_shared<SubscriptionState>();
  thrower->on_event = [](const HandEvent&) { throw std::runtime_error("user code"); };
  auto after = std::make_shared<SubscriptionState>();
  after->on_event = [&heard](const HandEvent& event) {
    heard.add(tagged("after ", event.message));
  };
  std::weak_ptr<SubscriptionState> weak_self = self;
  self->on_event = [&subs, &heard, weak_self](const HandEvent& event) {
    heard.add(tagged("self ", event.message));
    if (auto state = weak_self.lock()) subs.remove(state);
  };
  subs.add_events(self);
  subs.add_events(thrower);
  subs.add_events(after);
  subs.post_event(event_saying(std::string("a")));
  subs.post_event(event_saying(std::string("b")));
  EXPECT_EQ(heard.wait_for(3), (std::vector<std::string>{"self a", "after a", "after b"}));
  EXPECT_FALSE(self->active);
  subs.stop();
}

}  // namespace
}  // namespace dh3::detail
