// ClientMadeEvents without DDS: the OFFLINE a client tells for the hands of a
// service it lost, and the ONLINE it tells, once, when a status shows such a
// hand online again, without doubling the service's own ONLINE.

#include <gtest/gtest.h>

#include "client_made_events.hpp"

namespace dh3::detail {
namespace {

const HandAddress kLeft{"svc", "can0", 1};
const HandAddress kRight{"svc", "can0", 2};
constexpr std::uint64_t kMadeNs = 1'700'000'000'000'000'000U;

HandStatus status_of(const HandAddress& address, bool online = true) {
  HandStatus status;
  status.address = address;
  status.name = "left";
  status.online = online;
  status.position = 30;
  status.target_position = 500;
  status.firmware_version = 0x04010200;
  return status;
}

HandEvent service_event(const HandAddress& address, EventKind kind) {
  HandEvent event;
  event.hand = address;
  event.kind = kind;
  return event;
}

/// A client that told kLeft OFFLINE, then ONLINE for a status of `incarnation`.
ClientMadeEvents told_online_from(const std::string& incarnation) {
  ClientMadeEvents made;
  made.offline(status_of(kLeft), "lost", kMadeNs);
  EXPECT_TRUE(made.online(incarnation, status_of(kLeft), kMadeNs));
  return made;
}

TEST(ClientMadeEvents, TheOfflineEventSaysWhereTheHandWasAndWhy) {
  ClientMadeEvents made;
  const HandEvent event = made.offline(status_of(kLeft), "service 'svc' left the domain", kMadeNs);
  EXPECT_EQ(event.hand, kLeft);
  EXPECT_EQ(event.name, "left");
  EXPECT_EQ(event.kind, EventKind::offline);
  EXPECT_EQ(event.position, 30);
  EXPECT_EQ(event.target, 500);
  EXPECT_EQ(event.message, "service 'svc' left the domain");
  EXPECT_EQ(event.timestamp_ns, kMadeNs);  // when the client made it
  EXPECT_TRUE(event.from_client);
}

TEST(ClientMadeEvents, TheTakenOverEventSaysWhoServesTheHandNowAndWhoDidBefore) {
  const HandEvent event = ClientMadeEvents::taken_over(status_of(kLeft, false), "pid 1 on 'pc-a'",
                                                       "pid 2 on 'pc-b'", kMadeNs);
  EXPECT_EQ(event.kind, EventKind::taken_over);
  EXPECT_EQ(event.hand, kLeft);
  EXPECT_EQ(event.position, 30);
  EXPECT_TRUE(event.from_client);
  EXPECT_EQ(event.timestamp_ns, kMadeNs);
  EXPECT_EQ(event.message,
            "service 'svc' is now served by pid 2 on 'pc-b', which took over from pid 1 on 'pc-a'");
}

TEST(ClientMadeEvents, AHandToldOfflineIsToldOnlineOnceWhenAStatusShowsItOnline) {
  ClientMadeEvents made;
  made.offline(status_of(kLeft), "lost", kMadeNs);
  // The new incarnation's first status: its hand not answering yet.
  EXPECT_FALSE(made.online("B", status_of(kLeft, false), kMadeNs + 1));
  const auto online = made.online("B", status_of(kLeft), kMadeNs + 2);
  ASSERT_TRUE(online);
  EXPECT_EQ(online->kind, EventKind::online);
  EXPECT_EQ(online->hand, kLeft);
  EXPECT_EQ(online->timestamp_ns, kMadeNs + 2);
  EXPECT_EQ(online->value, 0x04010200);  // the firmware version, as the service's ONLINE
  EXPECT_TRUE(online->from_client);
  EXPECT_EQ(online->message, "service 'svc' is back");
  EXPECT_FALSE(made.online("B", status_of(kLeft), kMadeNs + 3)) << "told twice";
}

TEST(ClientMadeEvents, AHandTheStoppingServiceToldOfflineIsToldOnlineByItsNextIncarnation) {
  ClientMadeEvents made;
  // A service that stops tells its hands OFFLINE itself ("service stopping").
  EXPECT_TRUE(made.passes("A", service_event(kLeft, EventKind::offline)));
  // Within the incarnation, its own ONLINE comes: the client tells none.
  EXPECT_FALSE(made.online("A", status_of(kLeft), kMadeNs));
  const auto online = made.online("B", status_of(kLeft), kMadeNs);
  ASSERT_TRUE(online);
  EXPECT_EQ(online->kind, EventKind::online);
  EXPECT_TRUE(online->from_client);
}

TEST(ClientMadeEvents, AHandOfflineAndBackWithinOneIncarnationGetsOnlyTheServicesOnline) {
  ClientMadeEvents made;
  EXPECT_TRUE(made.passes("A", service_event(kLeft, EventKind::offline)));
  EXPECT_FALSE(made.online("A", status_of(kLeft), kMadeNs));
  EXPECT_TRUE(made.passes("A", service_event(kLeft, EventKind::online)));
  EXPECT_FALSE(made.online("B", status_of(kLeft), kMadeNs)) << "nothing owed any more";
}

TEST(ClientMadeEvents, AHandNeverToldOfflineIsNotToldOnline) {
  ClientMadeEvents made;
  made.offline(status_of(kLeft), "lost", kMadeNs);
  EXPECT_FALSE(made.online("B", status_of(kRight), kMadeNs));
}

TEST(ClientMadeEvents, AStatusStillMarkedLostOwesNothingYet) {
  ClientMadeEvents made;
  made.offline(status_of(kLeft), "lost", kMadeNs);
  HandStatus lost = status_of(kLeft, false);
  lost.service_lost = true;
  EXPECT_FALSE(made.online("A", lost, kMadeNs));
  EXPECT_TRUE(made.online("A", status_of(kLeft), kMadeNs));
}

TEST(ClientMadeEvents, TheServicesOwnOnlineAfterTheClientsIsADouble) {
  ClientMadeEvents made = told_online_from("B");
  EXPECT_FALSE(made.passes("B", service_event(kLeft, EventKind::online)));
  // Later ones of the same incarnation are news again.
  EXPECT_TRUE(made.passes("B", service_event(kLeft, EventKind::offline)));
  EXPECT_TRUE(made.passes("B", service_event(kLeft, EventKind::online)));
}

TEST(ClientMadeEvents, TheServicesOwnOnlineBeforeAnyStatusPaysWhatWasOwed) {
  ClientMadeEvents made;
  made.offline(status_of(kLeft), "lost", kMadeNs);
  EXPECT_TRUE(made.passes("B", service_event(kLeft, EventKind::online)));
  EXPECT_FALSE(made.online("B", status_of(kLeft), kMadeNs)) << "the service told it already";
}

TEST(ClientMadeEvents, AnyOtherEventOfTheIncarnationEndsTheWaitForItsOnline) {
  ClientMadeEvents made = told_online_from("B");
  EXPECT_TRUE(made.passes("B", service_event(kLeft, EventKind::arrived)));
  // Its ONLINE would have come before that ARRIVED: this one is a new one.
  EXPECT_TRUE(made.passes("B", service_event(kLeft, EventKind::online)));
}

TEST(ClientMadeEvents, AnotherIncarnationsOnlineIsNotTakenForADouble) {
  ClientMadeEvents made = told_online_from("B");
  EXPECT_TRUE(made.passes("C", service_event(kLeft, EventKind::online)));
}

}  // namespace
}  // namespace dh3::detail
