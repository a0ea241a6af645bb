// A bus full of hands: every one of them reaches the client. Fast DDS keeps
// 10 instances per keyed writer and reader unless told otherwise, which once
// let the 11th hand's status vanish (the contract's QoS lifts the limit).

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "client_fixture.hpp"

namespace dh3::test {
namespace {

TEST(ClientManyHands, TheStatusOfEveryOneOf255HandsReachesTheClient) {
  std::string ids;
  // Appended, not "literal" + std::string: GCC 12 warns falsely about that at -O3
  // (-Wrestrict inside libstdc++'s string insert, GCC bugs 105329, 105651).
  for (int id = 1; id <= 255; ++id) ids.append(id == 1 ? "" : ",").append(std::to_string(id));
  RunningService service("buses:\n  - name: bus0\n    spec: sim:" + ids + "\n");
  ASSERT_TRUE(service.started());
  Client client(client_options());
  ASSERT_TRUE(client.connected()) << client.error();

  ASSERT_TRUE(client.wait_for_service(test_service_name(), kClientDeadline));
  // wait_for_statuses: every hand the service lists has a status here.
  ASSERT_TRUE(client.wait_for_statuses(kClientDeadline));
  std::set<std::uint16_t> seen;
  for (const auto& status : client.hands()) {
    if (status.address.service == test_service_name()) seen.insert(status.address.can_id);
  }
  EXPECT_EQ(seen.size(), 255U);
  EXPECT_TRUE(client.hand(hand_address(255))
                  .wait_until([](const HandStatus& s) { return s.online; }, kClientDeadline));
  const auto info = client.service(test_service_name());
  ASSERT_TRUE(info);
  ASSERT_EQ(info->buses.size(), 1U);
  EXPECT_EQ(info->buses[0].hands.size(), 255U);
}

}  // namespace
}  // namespace dh3::test
