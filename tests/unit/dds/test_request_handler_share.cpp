// RequestHandler and its ClientShare on a bus whose loop never runs, so what
// it takes on stays in flight: scans beyond a caller's share are answered BUSY
// at once, counted by the participant that wrote them, never by client_id.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "dh3/sim/sim_bus.hpp"
#include "expiry_timer.hpp"
#include "hand_directory.hpp"
#include "lease_table.hpp"
#include "recording_reply_sink.hpp"
#include "request_handler.hpp"
#include "status_publisher.hpp"

namespace dh3::dds {
namespace {

using ::testing::HasSubstr;

class Unobserved final : public hand::HandObserver {
 public:
  void on_state(const hand::HandState& /*state*/) override {}
  void on_event(const hand::HandEvent& /*event*/) override {}
  void on_link(bus::LinkState /*state*/) override {}
};

class RequestHandlerShareTest : public ::testing::Test {
 protected:
  RequestHandlerShareTest() {
    schedulers_.push_back(std::make_unique<hand::BusScheduler>(
        "bus0",
        std::make_unique<sim::SimBus>("sim:1", std::vector<sim::SimHandOptions>{{}}, clock_),
        std::vector<hand::HandConfig>{{1, "left"}}, hand::SchedulerOptions{}, clock_, observer_));
    directory_.add_bus("bus0", schedulers_.back()->roster());
    statuses_.add_bus("bus0", "sim:1", {1});
  }
  ~RequestHandlerShareTest() override { handler_.cancel_scans(); }

  /// A SCAN of bus0 written by participant `writer` under `client_id`.
  void scan(const std::string& writer, const std::string& client_id, std::uint64_t seq) {
    msg::CommandRequest r;
    r.client_id(client_id);
    r.request_seq(seq);
    r.hand().service("dh3");
    r.hand().bus("bus0");
    r.command(msg::SCAN);
    handler_.handle(r, Caller{writer, writer + "@cell-pc"}, false);
  }

  ServiceOptions options_;
  FakeClock clock_;
  ClientShare share_{2};  ///< outlives the schedulers, whose completions hold its tickets
  LeaseTable leases_{clock_};
  HandDirectory directory_;
  Unobserved observer_;
  Schedulers schedulers_;  // never started: scans stay pending until cancel_scans()
  StatusPublisher statuses_{options_, clock_, leases_, directory_};
  RecordingReplySink sink_;
  ExpiryTimer timer_{[] { return std::optional<TimePoint>{}; }, [] {}};
  RequestHandler handler_{
      {options_, directory_, leases_, schedulers_, statuses_, sink_, timer_, share_}};
};

TEST_F(RequestHandlerShareTest, ScansBeyondAWritersShareAreBusyAtOnceAndOthersAreTaken) {
  scan("aa01", "aa01", 1);
  scan("aa01", "aa01", 2);
  EXPECT_TRUE(sink_.replies.empty()) << "scans in flight were answered at once";
  scan("aa01", "aa01", 3);
  ASSERT_EQ(sink_.replies.size(), 1u);
  EXPECT_EQ(sink_.replies.back().request_seq(), 3u);
  EXPECT_EQ(sink_.replies.back().code(), msg::BUSY);
  EXPECT_THAT(sink_.replies.back().message(),
              HasSubstr("'aa01@cell-pc' (participant aa01) has 2 requests in flight; at most 2"));
  // Another writer has its own share, whatever client_id it writes.
  scan("bb02", "aa01", 4);
  EXPECT_EQ(sink_.replies.size(), 1u) << "another participant's scan was refused";
  EXPECT_EQ(share_.in_flight("bb02"), 1u);
  EXPECT_EQ(share_.in_flight("aa01"), 2u);
}

TEST_F(RequestHandlerShareTest, AnAnsweredScanFreesItsSlot) {
  scan("aa01", "aa01", 1);
  scan("aa01", "aa01", 2);
  handler_.cancel_scans();
  ASSERT_EQ(sink_.replies.size(), 2u);
  EXPECT_EQ(share_.in_flight("aa01"), 0u);
  scan("aa01", "aa01", 3);
  EXPECT_EQ(sink_.replies.size(), 2u) << "a scan after the answers was refused";
}

}  // namespace
}  // namespace dh3::dds
