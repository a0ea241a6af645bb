// Floods from one participant: requests written by a participant that never
// reads its replies, and more scans at once than a client's share. The
// service holds at most its cap of replies for such a client (the newest),
// answers a client beyond its share BUSY saying why, and answers another
// client's command meanwhile.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "reliability_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::HasSubstr;

// The service's bounds (service/dds/src/reply_gate.hpp, client_share.hpp),
// written out: the test checks the figures the docs give.
constexpr std::uint64_t kHeldPerClient = 256;
constexpr int kInFlightPerClient = 64;
/// The writer's history is KEEP_LAST 64: a batch of requests is delivered
/// before the next is written, so none is overwritten unsent.
constexpr int kBatch = 50;

class Floods : public ::testing::Test {
 protected:
  void SetUp() override {
    // Probes 20 ms apart: a scan takes about 5 s, so a client's scans stay
    // in flight while it writes more.
    config_ = std::make_unique<TempFile>(
        "buses:\n  - name: bus0\n    spec: sim\n    command_interval_ms: 2\n"
        "    probe_spacing_ms: 20\n    hands: [{id: 1}, {id: 2}, {id: 3}]\n");
    service_ = std::make_unique<ServiceProcess>(
        std::vector<std::string>{"--config", config_->path(), "--log-level", "warn"});
    ASSERT_TRUE(service_->started());
    other_ = connected_client(service_->name(), "dh3-test-other");
    ASSERT_TRUE(other_) << "the service never answered";
    flood_ = std::make_unique<DdsTestClient>(test_domain(), "dh3-test-flood",
                                             DdsTestClient::Replies::none);
    ASSERT_TRUE(flood_->ok());
    ASSERT_TRUE(flood_->wait_request_reader()) << "the service's request reader never matched";
  }

  msg::HandAddress hand(std::uint16_t id) const {
    return DdsTestClient::hand(service_->name(), "bus0", id);
  }

  /// `count` requests from the flooding client, every one delivered.
  std::vector<std::uint64_t> flood(int count, const msg::CommandRequest& request) {
    std::vector<std::uint64_t> seqs;
    for (int i = 0; i < count; ++i) {
      seqs.push_back(flood_->send(request));
      if ((i + 1) % kBatch == 0) {
        EXPECT_TRUE(flood_->wait_delivered());
      }
    }
    EXPECT_TRUE(flood_->wait_delivered());
    return seqs;
  }

  std::unique_ptr<TempFile> config_;
  std::unique_ptr<ServiceProcess> service_;
  std::unique_ptr<DdsTestClient> other_;
  std::unique_ptr<DdsTestClient> flood_;
};

TEST_F(Floods, AClientThatNeverReadsItsRepliesHasOnlyTheNewestHeldAndOthersAreAnswered) {
  // Answered at once (an empty bus is INVALID_ARGUMENT): every reply goes to
  // the gate while the flood is taken.
  const auto seqs = flood(600, flood_->request(DdsTestClient::hand(service_->name(), "", 1),
                                               msg::READ_REGISTER, 0, 0x0602));
  // Delivered after the whole flood: taken with its last batch at the latest,
  // where the two clients' requests are served in turn.
  const auto answer = other_->call(hand(1), msg::SET_CLOSING_FORCE, 50);
  ASSERT_TRUE(answer) << "another client's command got no reply during the flood";
  EXPECT_EQ(answer->code(), msg::OK) << answer->message();
  // Sent after that reply, so taken after the whole flood was served.
  ASSERT_EQ(other_->call(hand(2), msg::SET_CLOSING_FORCE, 50)->code(), msg::OK);

  // A reply reader at last: what was held comes out, the newest only. (Not
  // every one of them: the writer's history keeps the last 64 unacknowledged,
  // so of a release this large some may be pushed out before they are sent.)
  flood_->read_replies();
  EXPECT_TRUE(flood_->wait_reply(seqs.back())) << "the newest held reply never came";
  // Waiting the whole grace is the point: a reply beyond the cap comes late.
  EXPECT_FALSE(flood_->wait_replies_to(flood_->client_id(), kHeldPerClient + 1, kDuplicateGrace))
      << flood_->replies_to(flood_->client_id()) << " replies of 600 were held, at most "
      << kHeldPerClient;
  const std::uint64_t first_kept = seqs.back() - kHeldPerClient + 1;
  for (std::uint64_t seq = seqs.front(); seq < first_kept; ++seq) {
    ASSERT_EQ(flood_->reply_count(seq), 0u)
        << "reply " << seq << " was kept, older than the " << kHeldPerClient << " newest";
  }
  std::printf("600 requests without a reply reader: %zu replies held and sent\n",
              flood_->replies_to(flood_->client_id()));
}

TEST_F(Floods, AClientOverItsShareIsAnsweredBusySayingWhyWhileAnotherIsServed) {
  flood_->read_replies();
  const auto seqs = flood(100, flood_->request(hand(0), msg::SCAN));
  // The flood's scans are in flight and its others BUSY; another client's
  // command is served.
  const auto answer = other_->call(hand(1), msg::SET_CLOSING_FORCE, 50);
  ASSERT_TRUE(answer);
  EXPECT_EQ(answer->code(), msg::OK) << answer->message();

  int ok = 0;
  int busy = 0;
  for (const auto seq : seqs) {
    const auto reply = flood_->wait_reply(seq, std::chrono::seconds(60));
    ASSERT_TRUE(reply) << "no reply to scan " << seq;
    if (reply->code() == msg::BUSY) {
      ++busy;
      EXPECT_THAT(reply->message(),
                  HasSubstr("requests in flight; at most " + std::to_string(kInFlightPerClient)));
    } else {
      EXPECT_EQ(reply->code(), msg::OK) << reply->message();
      ++ok;
    }
  }
  std::printf("100 scans at once: %d OK, %d BUSY\n", ok, busy);
  EXPECT_GE(busy, 1) << "100 scans never went beyond a client's share";
  EXPECT_GE(ok, kInFlightPerClient) << "fewer scans than a client's share were served";
  EXPECT_FALSE(flood_->wait_duplicate_reply(kDuplicateGrace));
}

}  // namespace
}  // namespace dh3::test
