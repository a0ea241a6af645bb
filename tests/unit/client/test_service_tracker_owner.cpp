// ServiceTracker with owner claims (idl/include/dh3/contract/ownership.hpp), without DDS: the
// owner is believed and nothing else of its name; an owner whose liveliness
// lapses is lost at once, and found again when it asserts again.

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <optional>
#include <vector>

#include "service_tracker.hpp"

namespace dh3::detail {
namespace {

using Endpoint = ServiceTracker::Endpoint;
using Outcome = ServiceTracker::Outcome;

contract::OwnerClaim claim(const std::string& participant, std::uint64_t epoch,
                           std::uint64_t started_ns) {
  contract::OwnerClaim c;
  c.participant = participant;
  c.service = "svc";
  c.host = "pc-" + participant;
  c.pid = 42;
  c.started_ns = started_ns;
  c.epoch = epoch;
  return c;
}

/// `prefix` serves svc: its claim arrived and it asserts its liveliness.
void serve(ServiceTracker& tracker, const std::string& prefix, std::uint64_t epoch,
           std::uint64_t started_ns) {
  Outcome ignored;
  tracker.take_claim(claim(prefix, epoch, started_ns), ignored);
  tracker.owner_alive(prefix, true);
}

TEST(TrackerOwner, ALapsedLivelinessLosesTheServiceAtOnceSayingWhy) {
  ServiceTracker tracker;
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored);
  serve(tracker, "A", 1, 10);
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  EXPECT_TRUE(tracker.alive("svc"));
  const Outcome lapsed = tracker.owner_alive("A", false);
  EXPECT_TRUE(lapsed.lost_service);
  EXPECT_EQ(lapsed.lost, "A");
  EXPECT_NE(lapsed.why.find("stopped asserting it lives"), std::string::npos) << lapsed.why;
  EXPECT_NE(lapsed.why.find("killed, frozen or cut off"), std::string::npos) << lapsed.why;
  EXPECT_NE(lapsed.why.find("pc-A"), std::string::npos) << lapsed.why;
  EXPECT_FALSE(tracker.alive("svc"));
  // What it still sends (it is frozen, or cut off and back) is not believed.
  Outcome late;
  EXPECT_FALSE(tracker.note_participant("A", "svc", late));
  EXPECT_FALSE(tracker.believed("A", "svc"));
}

TEST(TrackerOwner, AClaimWhoseLivelinessIsNotSeenYetIsNotLost) {
  // The claim sample may arrive before the first assertion (a client that
  // starts beside a busy service): unknown is not dead.
  ServiceTracker tracker;
  Outcome first;
  tracker.note_participant("A", "svc", first);
  Outcome claimed;
  tracker.take_claim(claim("A", 1, 10), claimed);
  EXPECT_FALSE(claimed.lost_service) << claimed.why;
  EXPECT_TRUE(tracker.alive("svc"));
  EXPECT_TRUE(tracker.believed("A", "svc"));
  const Outcome alive = tracker.owner_alive("A", true);
  EXPECT_FALSE(alive.lost_service);
  EXPECT_TRUE(alive.regained.empty()) << "it was never lost";
  EXPECT_TRUE(tracker.owner_alive("A", false).lost_service) << "a lapse after it was seen is";
}

/// A looker that reports `states` in turn (the last one once they run out),
/// counting its looks.
struct ScriptedLooks {
  std::vector<ReceiveState> states;
  std::size_t looks = 0;
  std::function<ReceiveState()> looker() {
    return [this] {
      const ReceiveState state = states[std::min(looks, states.size() - 1)];
      ++looks;
      return state;
    };
  }
};

TEST(TrackerOwner, AStatusAfterTheAssumedLapseOfAnOwnerFastDdsNeverReportedIsItsProofOfLife) {
  using namespace std::chrono_literals;
  ScriptedLooks current{{ReceiveState::current}};
  ServiceTracker tracker;
  tracker.set_receive_looker(current.looker());
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored);
  const auto t0 = std::chrono::steady_clock::time_point{} + 1h;
  tracker.take_claim(claim("A", 1, 10), ignored, t0);  // its liveliness report never comes
  tracker.confirm_lapses(t0 + contract::kOwnerLease);
  tracker.confirm_lapses(t0 + contract::kOwnerLease + contract::kOwnerLapseConfirm);
  ASSERT_FALSE(tracker.alive("svc")) << "a claim that never asserted is lost";
  Outcome status;
  EXPECT_TRUE(tracker.note_status("A", "svc", status));
  EXPECT_EQ(status.regained, "A");
  EXPECT_TRUE(tracker.alive("svc"));
  // Fast DDS's next report of it is a lapse, then its return.
  EXPECT_FALSE(tracker.owner_liveliness_changed("A", -1));
  EXPECT_TRUE(tracker.owner_liveliness_changed("A", +1));

  // One whose liveliness Fast DDS reported and then lapsed stays lost: what it
  // still sends is no proof (it is frozen, or cut off and back).
  ServiceTracker reported;
  reported.set_receive_looker(current.looker());
  reported.note_participant("B", "svc", ignored);
  reported.take_claim(claim("B", 1, 10), ignored, t0);
  ASSERT_TRUE(reported.owner_liveliness_changed("B", +1));
  reported.owner_alive("B", true);
  ASSERT_FALSE(reported.owner_liveliness_changed("B", -1));
  reported.owner_lapsed("B", t0 + 1s);
  reported.confirm_lapses(t0 + 1s);
  reported.confirm_lapses(t0 + 1s + contract::kOwnerLapseConfirm);
  ASSERT_FALSE(reported.alive("svc"));
  Outcome late;
  EXPECT_FALSE(reported.note_status("B", "svc", late));
  EXPECT_FALSE(reported.alive("svc"));
}

TEST(TrackerOwner, ALapseThatStandsLosesTheServiceAndItsCallsAtOnceIfThisProcessIsCurrent) {
  using namespace std::chrono_literals;
  ScriptedLooks looks{{ReceiveState::current}};
  ServiceTracker tracker;
  tracker.set_receive_looker(looks.looker());
  serve(tracker, "A", 1, 10);
  const auto t0 = std::chrono::steady_clock::time_point{} + 1h;
  EXPECT_EQ(tracker.next_lapse(), std::chrono::steady_clock::time_point::max());
  // A lapse the owner's next assertion overturns.
  tracker.owner_lapsed("A", t0);
  EXPECT_EQ(tracker.next_lapse(), t0) << "a look at once";
  EXPECT_TRUE(tracker.confirm_lapses(t0).empty());
  EXPECT_EQ(looks.looks, 1U);
  EXPECT_TRUE(tracker.alive("svc")) << "not believed yet";
  EXPECT_EQ(tracker.next_lapse(), t0 + contract::kOwnerLapseConfirm);
  EXPECT_TRUE(tracker.confirm_lapses(t0 + contract::kOwnerLapseConfirm - 1ms).empty());
  EXPECT_FALSE(tracker.owner_alive("A", true).lost_service);
  EXPECT_TRUE(tracker.confirm_lapses(t0 + 10s).empty()) << "overturned";
  EXPECT_TRUE(tracker.alive("svc"));

  // A lapse that stands: the service is lost and its calls in flight end with it.
  const auto t1 = t0 + 20s;
  tracker.owner_lapsed("A", t1);
  tracker.owner_lapsed("A", t1 + 100ms);  // reported again: the first one counts
  EXPECT_TRUE(tracker.confirm_lapses(t1).empty());
  const auto lost = tracker.confirm_lapses(t1 + contract::kOwnerLapseConfirm);
  ASSERT_EQ(lost.size(), 2U);
  EXPECT_TRUE(lost[0].lost_service);
  EXPECT_EQ(lost[0].lost, "A");
  EXPECT_NE(lost[0].why.find("killed, frozen or cut off"), std::string::npos) << lost[0].why;
  EXPECT_FALSE(lost[1].lost_service) << "already lost";
  EXPECT_EQ(lost[1].end_calls_of, "A");
  EXPECT_EQ(lost[1].why, lost[0].why);
  EXPECT_FALSE(tracker.alive("svc"));
  EXPECT_EQ(tracker.next_lapse(), std::chrono::steady_clock::time_point::max());
}

TEST(TrackerOwner, ALapseSeenWhileThisProcessIsBehindEndsNoCallUntilItCaughtUp) {
  using namespace std::chrono_literals;
  using State = ReceiveState;
  // Behind at the report and for 200 ms more, then current.
  ScriptedLooks looks{{State::behind, State::behind, State::behind, State::behind, State::behind,
                       State::current}};
  ServiceTracker tracker;
  tracker.set_receive_looker(looks.looker());
  serve(tracker, "A", 1, 10);
  const auto t0 = std::chrono::steady_clock::time_point{} + 1h;
  tracker.owner_lapsed("A", t0);
  auto now = t0;
  std::vector<Outcome> outcomes;
  std::optional<std::chrono::steady_clock::time_point> calls_ended;
  while (!calls_ended && now < t0 + 10s) {
    for (auto& outcome : tracker.confirm_lapses(now)) {
      if (!outcome.end_calls_of.empty()) calls_ended = now;
      outcomes.push_back(std::move(outcome));
    }
    now = tracker.next_lapse();
  }
  ASSERT_FALSE(outcomes.empty());
  EXPECT_TRUE(outcomes[0].lost_service) << "its hands go offline all the same";
  EXPECT_TRUE(outcomes[0].keep_calls);
  ASSERT_TRUE(calls_ended) << "caught up, and the lapse still stands";
  // The first current look at t0 + 5 looks; the calls end once it stayed
  // current for the span.
  const auto caught_up = t0 + 5 * LapseJudge::kLookAgain;
  EXPECT_EQ(*calls_ended, caught_up + LapseJudge::kCaughtUpSpan);

  // Overturned while behind: no call ends, whatever comes later.
  ScriptedLooks behind{{State::behind}};
  ServiceTracker stalled;
  stalled.set_receive_looker(behind.looker());
  serve(stalled, "A", 1, 10);
  stalled.owner_lapsed("A", t0);
  EXPECT_TRUE(stalled.confirm_lapses(t0).empty());
  EXPECT_EQ(stalled.confirm_lapses(t0 + 3s).size(), 1U) << "lost, its calls kept";
  EXPECT_EQ(stalled.next_lapse(), t0 + 3s + LapseJudge::kLookAgain) << "no limit while behind";
  EXPECT_EQ(stalled.owner_alive("A", true).regained, "A");
  EXPECT_TRUE(stalled.confirm_lapses(t0 + 1h).empty()) << "nothing ends";
}

TEST(TrackerOwner, ALapseWhoseReceiveQueuesCannotBeSeenEndsItsCallsOnlyAfterTheBlindConfirm) {
  using namespace std::chrono_literals;
  ServiceTracker tracker;  // no looker: the queues cannot be seen
  serve(tracker, "A", 1, 10);
  const auto t1 = std::chrono::steady_clock::time_point{} + 1h;
  tracker.owner_lapsed("A", t1);
  EXPECT_TRUE(tracker.confirm_lapses(t1).empty());
  auto lost = tracker.confirm_lapses(t1 + contract::kOwnerLapseConfirm);
  ASSERT_EQ(lost.size(), 1U);
  EXPECT_TRUE(lost[0].lost_service);
  EXPECT_TRUE(lost[0].keep_calls);
  EXPECT_FALSE(tracker.alive("svc"));
  EXPECT_EQ(tracker.next_lapse(), t1 + contract::kOwnerLapseCallConfirm);
  EXPECT_TRUE(tracker.confirm_lapses(t1 + contract::kOwnerLapseCallConfirm - 1ms).empty());
  const auto calls = tracker.confirm_lapses(t1 + contract::kOwnerLapseCallConfirm);
  ASSERT_EQ(calls.size(), 1U);
  EXPECT_FALSE(calls[0].lost_service) << "already lost";
  EXPECT_EQ(calls[0].end_calls_of, "A");
  EXPECT_EQ(calls[0].why, lost[0].why);
  EXPECT_EQ(tracker.next_lapse(), std::chrono::steady_clock::time_point::max());
}

TEST(TrackerOwner, AClaimantNeverSeenAssertingIsLostALeaseAfterItsClaim) {
  using namespace std::chrono_literals;
  const auto t0 = std::chrono::steady_clock::time_point{} + 1h;
  ServiceTracker tracker;
  Outcome ignored;
  tracker.take_claim(claim("A", 1, 10), ignored, t0);
  EXPECT_TRUE(tracker.alive("svc")) << "unknown is not dead";
  EXPECT_TRUE(tracker.confirm_lapses(t0 + contract::kOwnerLease).empty());
  const auto lost =
      tracker.confirm_lapses(t0 + contract::kOwnerLease + contract::kOwnerLapseConfirm);
  ASSERT_EQ(lost.size(), 1U) << "killed before its first assertion reached us";
  EXPECT_TRUE(lost[0].lost_service);
  EXPECT_FALSE(tracker.alive("svc"));

  ServiceTracker seen;
  seen.take_claim(claim("A", 1, 10), ignored, t0);
  seen.owner_alive("A", true);
  EXPECT_TRUE(seen.confirm_lapses(t0 + 1h).empty()) << "it asserted: nothing to confirm";
  EXPECT_TRUE(seen.alive("svc"));
}

TEST(TrackerOwner, AnOwnerBackBeforeItsCallsEndedKeepsThem) {
  using namespace std::chrono_literals;
  ServiceTracker tracker;
  serve(tracker, "A", 1, 10);
  const auto t0 = std::chrono::steady_clock::time_point{} + 1h;
  tracker.owner_lapsed("A", t0);
  ASSERT_EQ(tracker.confirm_lapses(t0 + contract::kOwnerLapseConfirm).size(), 1U);
  const Outcome back = tracker.owner_alive("A", true);
  EXPECT_EQ(back.regained, "A");
  EXPECT_TRUE(tracker.alive("svc"));
  EXPECT_TRUE(tracker.confirm_lapses(t0 + 1h).empty()) << "no call ends";
}

TEST(TrackerOwner, AnOwnerThatAssertsAgainIsServedAgain) {
  ServiceTracker tracker;
  serve(tracker, "A", 1, 10);
  tracker.owner_alive("A", false);
  const Outcome back = tracker.owner_alive("A", true);
  EXPECT_FALSE(back.lost_service);
  EXPECT_EQ(back.regained, "A") << "its hands come back";
  EXPECT_TRUE(back.may_dispatch);
  EXPECT_TRUE(tracker.alive("svc"));
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  EXPECT_TRUE(tracker.believed("A", "svc"));
}

TEST(TrackerOwner, ADuplicateIsNeverBelievedNorMadeCurrent) {
  ServiceTracker tracker;
  serve(tracker, "A", 1, 10);
  Outcome dup;
  // A second service of the name in its claim window: a participant, no claim.
  EXPECT_FALSE(tracker.note_participant("B", "svc", dup));
  EXPECT_FALSE(tracker.believed("B", "svc"));
  ServiceInfo info;
  info.name = "svc";
  info.started_ns = 999;  // started later: before claims, that was a restart
  EXPECT_FALSE(tracker.take_info("B", info, dup));
  EXPECT_FALSE(dup.lost_service);
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  // Even once the owner died, the refused one does not become the service.
  tracker.owner_alive("A", false);
  EXPECT_FALSE(tracker.note_participant("A", "svc", dup));
  EXPECT_NE(tracker.incarnation("svc"), "B");
}

TEST(TrackerOwner, AHigherEpochTakesOverAndTheOldOwnersCallsAreLost) {
  ServiceTracker tracker;
  serve(tracker, "A", 1, 10);
  // Its claim alone decides: the sample came from a live writer.
  Outcome taken;
  tracker.take_claim(claim("B", 2, 5), taken);
  EXPECT_TRUE(taken.lost_service);
  EXPECT_EQ(taken.lost, "A");
  EXPECT_NE(taken.why.find("now served by"), std::string::npos) << taken.why;
  EXPECT_EQ(tracker.incarnation("svc"), "B");
  EXPECT_FALSE(tracker.believed("A", "svc"));
  EXPECT_TRUE(tracker.believed("B", "svc"));
  EXPECT_FALSE(tracker.owner_alive("B", true).lost_service)
      << "its first assertion changes nothing";
  EXPECT_EQ(tracker.incarnation("svc"), "B");
}

TEST(TrackerOwner, ANewOwnerEndsTheCallsOfALapsedOneAtOnce) {
  using namespace std::chrono_literals;
  ServiceTracker tracker;
  serve(tracker, "A", 1, 10);
  const auto t0 = std::chrono::steady_clock::time_point{} + 1h;
  tracker.owner_lapsed("A", t0);
  const auto lost = tracker.confirm_lapses(t0 + contract::kOwnerLapseConfirm);
  ASSERT_EQ(lost.size(), 1U);
  EXPECT_TRUE(lost[0].keep_calls) << "its calls wait for it a while";
  // Its standby takes over: the calls sent to A end now, not at the lapse's
  // call confirmation.
  Outcome taken;
  tracker.take_claim(claim("B", 2, 5), taken, t0 + contract::kOwnerLapseConfirm);
  EXPECT_EQ(taken.end_calls_of, "A");
  EXPECT_FALSE(taken.keep_calls);
  EXPECT_NE(taken.why.find("now served by"), std::string::npos) << taken.why;
  EXPECT_NE(taken.why.find("killed, frozen or cut off"), std::string::npos) << taken.why;
  EXPECT_EQ(tracker.incarnation("svc"), "B");
  (void)tracker.owner_alive("B", true);
  EXPECT_TRUE(tracker.confirm_lapses(t0 + contract::kOwnerLapseCallConfirm).empty())
      << "ended once";
}

TEST(TrackerOwner, AStandbyIsNotBelievedWhileItStandsBy) {
  ServiceTracker tracker;
  serve(tracker, "A", 1, 10);
  auto standby = claim("S", 1, 20);
  standby.standby = true;
  Outcome ignored;
  tracker.take_claim(standby, ignored);
  tracker.owner_alive("S", true);
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  EXPECT_FALSE(tracker.believed("S", "svc"));
  // The primary dies: nobody serves until the standby claims as active.
  tracker.owner_alive("A", false);
  EXPECT_FALSE(tracker.alive("svc"));
  standby.standby = false;
  standby.epoch = 2;
  Outcome takeover;
  tracker.take_claim(standby, takeover);
  EXPECT_TRUE(takeover.may_dispatch);
  EXPECT_EQ(tracker.incarnation("svc"), "S");
  EXPECT_TRUE(tracker.alive("svc"));
}

TEST(TrackerOwner, AnOwnerOfAnotherProcessSaysWhoTookOverFromWhom) {
  ServiceTracker tracker;
  Outcome first;
  tracker.take_claim(claim("A", 1, 10), first);
  EXPECT_TRUE(first.taken_over_by.empty()) << "the first owner seen takes over from nobody";
  tracker.owner_alive("A", true);
  tracker.owner_alive("A", false);  // killed
  auto standby = claim("S", 2, 20);
  Outcome takeover;
  tracker.take_claim(standby, takeover);
  EXPECT_EQ(takeover.service, "svc");
  EXPECT_EQ(takeover.taken_over_from, claim("A", 1, 10).describe());
  EXPECT_EQ(takeover.taken_over_by, standby.describe());
  // The same owner asserting again changes no hands.
  Outcome again;
  tracker.take_claim(standby, again);
  EXPECT_TRUE(again.taken_over_by.empty());
  EXPECT_TRUE(tracker.owner_alive("S", true).taken_over_by.empty());
}

TEST(TrackerOwner, TheOwnerLeavingHandsTheNameToTheNextLiveOwner) {
  ServiceTracker tracker;
  serve(tracker, "A", 2, 10);
  serve(tracker, "B", 1, 10);
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  const Outcome left = tracker.participant_left("A");
  EXPECT_TRUE(left.lost_service);
  EXPECT_EQ(tracker.incarnation("svc"), "B");
  EXPECT_TRUE(tracker.alive("svc"));
}

/// `prefix`'s request reader, reply writer and event writer matched ours at `now`.
void match_commands(ServiceTracker& tracker, const std::string& prefix,
                    std::chrono::steady_clock::time_point now) {
  for (const auto endpoint :
       {Endpoint::request_reader, Endpoint::reply_writer, Endpoint::event_writer}) {
    tracker.matched(endpoint, prefix, true, now);
  }
}

TEST(TrackerOwner, AClientReadingClaimsCallsAServiceReadyOnlyOnceItsOwnerWasSeenAlive) {
  // Ready before its owner writer matched, a kill right then would be seen
  // only at the participant lease.
  const auto t0 = std::chrono::steady_clock::now();
  ServiceTracker tracker;
  tracker.set_endpoints(true, true);
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored, t0);
  match_commands(tracker, "A", t0);
  EXPECT_FALSE(tracker.ready("svc")) << "its owner writer has not matched";
  tracker.matched(Endpoint::owner_writer, "A", true, t0);
  EXPECT_FALSE(tracker.ready("svc")) << "its liveliness was not seen";
  tracker.take_claim(claim("A", 1, 10), ignored, t0);
  EXPECT_FALSE(tracker.ready("svc")) << "a claim is not an assertion";
  const Outcome alive = tracker.owner_alive("A", true);
  EXPECT_TRUE(alive.may_dispatch);
  EXPECT_TRUE(tracker.ready("svc"));
  ASSERT_TRUE(tracker.find_ready("svc", false));
  // Its death is then seen by the owner lease.
  EXPECT_TRUE(tracker.owner_alive("A", false).lost_service);
  EXPECT_FALSE(tracker.ready("svc"));
}

TEST(TrackerOwner, AnAssertionBeforeTheClaimSampleDoesNotMakeTheServiceReady) {
  // The first assertion (a heartbeat) may arrive before the claim sample,
  // which a loaded client fetches in a round trip of its own. Ready then, a
  // kill before the sample arrives would find no claim to lose: the death
  // would be seen only at the participant lease.
  const auto t0 = std::chrono::steady_clock::now();
  ServiceTracker tracker;
  tracker.set_endpoints(true, true);
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored, t0);
  match_commands(tracker, "A", t0);
  tracker.matched(Endpoint::owner_writer, "A", true, t0);
  tracker.owner_alive("A", true);
  EXPECT_FALSE(tracker.ready("svc")) << "its claim has not arrived";
  tracker.take_claim(claim("A", 1, 10), ignored, t0);
  EXPECT_TRUE(tracker.ready("svc"));
  EXPECT_TRUE(tracker.owner_alive("A", false).lost_service);
}

TEST(TrackerOwner, AServiceWhoseOwnerWriterNeverShowsIsReadyAWaitAfterItsOtherEndpoints) {
  // Permissions that predate the owner topic: it is never matched, and the
  // service still serves, its death seen at the participant lease.
  using namespace std::chrono_literals;
  const auto t0 = std::chrono::steady_clock::now();
  ServiceTracker tracker;
  tracker.set_endpoints(true, true);
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored, t0);
  EXPECT_EQ(tracker.next_lapse(), std::chrono::steady_clock::time_point::max())
      << "the wait starts when its other endpoints matched, not at discovery";
  const auto t1 = t0 + 5s;
  match_commands(tracker, "A", t1);
  EXPECT_EQ(tracker.next_lapse(), t1 + ServiceTracker::kOwnerWait);
  EXPECT_TRUE(tracker.confirm_lapses(t1 + ServiceTracker::kOwnerWait - 1ms).empty());
  EXPECT_FALSE(tracker.ready("svc"));
  const auto waived = tracker.confirm_lapses(t1 + ServiceTracker::kOwnerWait);
  ASSERT_EQ(waived.size(), 1U);
  EXPECT_EQ(waived[0].service, "svc");
  EXPECT_TRUE(waived[0].may_dispatch) << "its waiting calls go out";
  EXPECT_FALSE(waived[0].lost_service);
  EXPECT_TRUE(tracker.ready("svc"));
  EXPECT_EQ(tracker.next_lapse(), std::chrono::steady_clock::time_point::max());
  EXPECT_TRUE(tracker.confirm_lapses(t1 + 1h).empty()) << "waived once";
  // An owner writer that matches after all is waited for again.
  tracker.matched(Endpoint::owner_writer, "A", true, t1 + 3s);
  EXPECT_FALSE(tracker.ready("svc"));
  tracker.owner_alive("A", true);
  EXPECT_FALSE(tracker.ready("svc")) << "its claim has not arrived";
  tracker.take_claim(claim("A", 1, 10), ignored, t1 + 3s);
  EXPECT_TRUE(tracker.ready("svc"));
}

TEST(TrackerOwner, MatchesBeforeTheClientsEndpointsAreKnownStartTheWaitThen) {
  // DDS may match a service while the client is still creating its readers.
  const auto t0 = std::chrono::steady_clock::now();
  ServiceTracker tracker;
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored, t0);
  tracker.matched(Endpoint::event_writer, "A", true, t0);
  const auto t1 = t0 + std::chrono::seconds(1);
  tracker.set_endpoints(false, true, t1);
  EXPECT_FALSE(tracker.ready("svc"));
  EXPECT_EQ(tracker.next_lapse(), t1 + ServiceTracker::kOwnerWait);
  EXPECT_EQ(tracker.confirm_lapses(t1 + ServiceTracker::kOwnerWait).size(), 1U);
  EXPECT_TRUE(tracker.ready("svc"));
}

TEST(TrackerOwner, AClientWithoutTheOwnerReaderDoesNotWaitForLiveliness) {
  const auto t0 = std::chrono::steady_clock::now();
  ServiceTracker tracker;
  tracker.set_endpoints(true, false);
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored, t0);
  match_commands(tracker, "A", t0);
  EXPECT_TRUE(tracker.ready("svc"));
  EXPECT_EQ(tracker.next_lapse(), std::chrono::steady_clock::time_point::max());
}

TEST(TrackerOwner, AReadOnlyClientWaitsForTheOwnerToo) {
  const auto t0 = std::chrono::steady_clock::now();
  ServiceTracker tracker;
  tracker.set_endpoints(false, true);
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored, t0);
  tracker.matched(Endpoint::event_writer, "A", true, t0);
  EXPECT_FALSE(tracker.ready("svc"));
  EXPECT_EQ(tracker.next_lapse(), t0 + ServiceTracker::kOwnerWait);
  tracker.take_claim(claim("A", 1, 10), ignored, t0);
  tracker.owner_alive("A", true);
  EXPECT_TRUE(tracker.ready("svc"));
}

}  // namespace
}  // namespace dh3::detail
