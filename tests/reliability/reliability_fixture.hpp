#pragma once
// What the reliability tests share: dh3-service on a TCP transfer box served
// by a dh3-sim process, reached through a proxy that records every frame the
// service sends and can cut the link or mangle the stream; a raw DDS client;
// and the check every test ends with: each request got exactly one reply, and
// no second one came within a grace period.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "integration/service/service_fixture.hpp"

namespace dh3::test {

/// How dh3-sim and the service's bus are set up for a test.
struct BoxOptions {
  std::vector<std::string> sim_args;  ///< added to dh3-sim's "--hands 1,2,3 ..."
  int init_time_ms = 50;              ///< how long a simulated initialization takes
  int reply_timeout_ms = 100;         ///< how long the service waits for an echo
};

/// A transfer-box bus "box" with hands 1-3 behind `spec`, paced fast.
inline std::string box_config(const std::string& spec, int reply_timeout_ms) {
  return "buses:\n  - name: box\n    spec: " + spec +
         "\n    command_interval_ms: 2\n    poll_interval_moving_ms: 20\n"
         "    poll_interval_idle_ms: 50\n    reply_timeout_ms: " +
         std::to_string(reply_timeout_ms) + "\n    hands: [{id: 1}, {id: 2}, {id: 3}]\n";
}

/// Waits for the reply to each of `seqs` (sent by `client` as `client_id`,
/// its own by default), then checks that within the grace period no request
/// of any client_id got a second reply. Returns the replies, in `seqs` order.
inline std::vector<msg::CommandReply> expect_one_reply_each(
    DdsTestClient& client, const std::vector<std::uint64_t>& seqs,
    const std::optional<std::string>& client_id = std::nullopt,
    std::chrono::milliseconds deadline = std::chrono::seconds(30)) {
  std::vector<msg::CommandReply> replies;
  for (const auto seq : seqs) {
    auto reply = client.wait_reply(seq, deadline, client_id);
    EXPECT_TRUE(reply) << "no reply to request " << seq;
    if (!reply) return replies;
    replies.push_back(std::move(*reply));
  }
  const auto duplicate = client.wait_duplicate_reply(kDuplicateGrace);
  EXPECT_FALSE(duplicate) << client.describe_replies(duplicate->second, duplicate->first);
  return replies;
}

/// dh3-sim with hands 1-3, the recording proxy in front of it and dh3-service
/// on the proxy; a raw client that waited for every hand to come online.
class BoxTest : public ::testing::Test {
 protected:
  /// Call as ASSERT_NO_FATAL_FAILURE(start()): the test cannot go on without.
  void start(const BoxOptions& options = {}) {
    std::vector<std::string> args{"--hands",          "1,2,3",
                                  "--reply-delay-ms", "1",
                                  "--init-time-ms",   std::to_string(options.init_time_ms)};
    args.insert(args.end(), options.sim_args.begin(), options.sim_args.end());
    sim_ = std::make_unique<SimProcess>(args);
    ASSERT_NE(sim_->port(), 0) << "dh3-sim did not start";
    proxy_ = std::make_unique<RecordingProxy>(sim_->port());
    ASSERT_NE(proxy_->port(), 0) << "the proxy did not start";
    before_start();
    config_ = std::make_unique<TempFile>(box_config(proxy_->bus_spec(), options.reply_timeout_ms));
    service_ = std::make_unique<ServiceProcess>(
        std::vector<std::string>{"--config", config_->path(), "--log-level", "warn"});
    ASSERT_TRUE(service_->started());
    client_ = connected_client(service_->name());
    ASSERT_TRUE(client_) << "the service never answered";
    for (std::uint16_t id = 1; id <= 3; ++id) {
      ASSERT_TRUE(client_->wait_status(hand(id), [](const auto& s) { return s.online(); }))
          << "hand " << id << " never online";
      ASSERT_TRUE(wait_read_afresh(id)) << "hand " << id << " never read afresh";
    }
  }

  /// Waits until the service has read hand `id`'s registers after it came
  /// online: those reads are re-sent on a timeout, each after a whole reply
  /// timeout and ahead of any request, so a test that mutes a hand during
  /// them would have its request wait for all of them. The rotation's status
  /// is their last read; any frame to the hand after it means it was answered
  /// (one frame in flight per hand).
  bool wait_read_afresh(std::uint16_t id) {
    constexpr char kHex[] = "0123456789ABCDEF";
    const std::string to_hand =
        std::string("FF FE FD FC ") + kHex[(id >> 4) & 0xF] + kHex[id & 0xF];
    const std::string last_read = to_hand + " 0F 02 00";
    const auto deadline = std::chrono::steady_clock::now() + kDdsDeadline;
    while (std::chrono::steady_clock::now() < deadline) {
      const auto frames = frames_as_hex(proxy_->sent());
      const auto read = std::find_if(frames.begin(), frames.end(),
                                     [&](const std::string& f) { return f.starts_with(last_read); });
      if (read != frames.end() && std::any_of(std::next(read), frames.end(), [&](const auto& f) {
            return f.starts_with(to_hand);
          })) {
        return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));  // polling, not a wait for time
    }
    return false;
  }

  /// Runs once the proxy is up, before the service connects to it.
  virtual void before_start() {}

  msg::HandAddress hand(std::uint16_t id) const {
    return DdsTestClient::hand(service_->name(), "box", id);
  }

  /// True while the service process has not exited.
  bool service_alive() { return !service_->process().wait_exit(std::chrono::milliseconds(0)); }

  std::unique_ptr<SimProcess> sim_;
  std::unique_ptr<RecordingProxy> proxy_;
  std::unique_ptr<TempFile> config_;
  std::unique_ptr<ServiceProcess> service_;
  std::unique_ptr<DdsTestClient> client_;
};

}  // namespace dh3::test
