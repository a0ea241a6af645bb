// A hand's initialize (std_srvs/srv/Trigger) and set_forces
// (rcl_interfaces/srv/SetParameters) services through dh3-ros2, called by an
// rmw_fastrtps-style client (ros_action_client.hpp): each takes the hand's
// lease and gives it back, is refused when another client holds the lease or
// a goal drives the hand, and a refused parameter sets nothing.

#include "ros2_action_fixture.hpp"

namespace dh3::test {
namespace {

namespace ss = std_srvs::srv::dds_;
namespace rm = rcl_interfaces::msg::dds_;
namespace rs = rcl_interfaces::srv::dds_;
using Trigger = RosServiceClient<ss::Trigger_Request_, ss::Trigger_Request_PubSubType,
                                 ss::Trigger_Response_, ss::Trigger_Response_PubSubType>;
using SetParameters =
    RosServiceClient<rs::SetParameters_Request_, rs::SetParameters_Request_PubSubType,
                     rs::SetParameters_Response_, rs::SetParameters_Response_PubSubType>;

constexpr std::uint8_t kInteger = 2;
constexpr std::uint8_t kDouble = 3;
constexpr std::uint8_t kString = 4;

rm::Parameter_ parameter(const std::string& name, std::uint8_t type, double value) {
  rm::Parameter_ p;
  p.name(name);
  p.value().type(type);
  if (type == kInteger) p.value().integer_value(static_cast<std::int64_t>(value));
  if (type == kDouble) p.value().double_value(value);
  if (type == kString) p.value().string_value(std::to_string(value));
  return p;
}

template <typename Service>
bool wait_ready(Service& service) {
  const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
  while (!service.ready()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

// A request written as soon as the client sees the server's reader matched
// may reach a server that has not matched the client's writer yet: seen here
// under load, such a first request got no reply (the request topic is
// VOLATILE, as ROS 2's services are; an rmw_fastrtps server is no different).
// Each test makes its clients first, so that matching completes both ways
// while it sets the hand up, as a ROS 2 client made at start-up would.
class Ros2HandServicesTest : public Ros2ActionFixture {
 protected:
  Trigger& initialize(std::uint16_t id) {
    auto& slot = initialize_[id];
    if (!slot) slot = std::make_unique<Trigger>(*participant_, hand_ros_name(id, "initialize"));
    EXPECT_TRUE(wait_ready(*slot)) << "the initialize service did not match";
    return *slot;
  }
  SetParameters& set_forces(std::uint16_t id) {
    auto& slot = set_forces_[id];
    if (!slot) {
      slot = std::make_unique<SetParameters>(*participant_, hand_ros_name(id, "set_forces"));
    }
    EXPECT_TRUE(wait_ready(*slot)) << "the set_forces service did not match";
    return *slot;
  }
  std::optional<rs::SetParameters_Response_> call_set_forces(
      std::uint16_t id, std::vector<rm::Parameter_> parameters) {
    rs::SetParameters_Request_ request;
    request.parameters(std::move(parameters));
    return set_forces(id).call(request, kClientDeadline);
  }

  std::map<std::uint16_t, std::unique_ptr<Trigger>> initialize_;
  std::map<std::uint16_t, std::unique_ptr<SetParameters>> set_forces_;
};

TEST_F(Ros2HandServicesTest, InitializeTakesTheLeaseAndGivesItBack) {
  auto& service = initialize(1);
  auto hand = client_.hand(hand_address(1));
  Client other(client_options());
  auto held = other.hand(hand_address(1));
  ASSERT_TRUE(other.wait_for_hand(hand_spec(1)));
  ASSERT_TRUE(held.acquire_lease(std::chrono::seconds(30)));
  const auto refused = service.call(ss::Trigger_Request_(), kClientDeadline);
  ASSERT_TRUE(refused);
  EXPECT_FALSE(refused->success());
  EXPECT_NE(refused->message().find("lease"), std::string::npos) << refused->message();
  EXPECT_FALSE(hand.status()->initialized) << "initialized under another client's lease";
  ASSERT_TRUE(held.release_lease());

  const auto done = service.call(ss::Trigger_Request_(), kClientDeadline);
  ASSERT_TRUE(done);
  EXPECT_TRUE(done->success()) << done->message();
  EXPECT_TRUE(hand.wait_until([](const HandStatus& s) { return s.initialized; }));
  EXPECT_TRUE(hand.wait_until([](const HandStatus& s) { return s.lease_holder.empty(); }))
      << "the service kept the lease";
  EXPECT_TRUE(held.move_to(30)) << "another client cannot drive the hand after the service";
}

TEST_F(Ros2HandServicesTest, SetForcesSetsNewtonsAsPercent) {
  set_forces(2);
  auto hand = client_.hand(hand_address(2));
  ASSERT_TRUE(hand.initialize());
  const auto set = call_set_forces(
      2, {parameter("closing_force", kDouble, 45.0), parameter("opening_force", kInteger, 27)});
  ASSERT_TRUE(set);
  ASSERT_EQ(set->results().size(), 2U);
  EXPECT_TRUE(set->results()[0].successful()) << set->results()[0].reason();
  EXPECT_TRUE(set->results()[1].successful()) << set->results()[1].reason();
  const auto status = hand.wait_until(
      [](const HandStatus& s) { return s.closing_force == 50 && s.opening_force == 30; });
  EXPECT_TRUE(status) << "closing " << hand.status()->closing_force << " %, opening "
                      << hand.status()->opening_force << " %; wanted 50 (45 N) and 30 (27 N)";
  EXPECT_TRUE(hand.wait_until([](const HandStatus& s) { return s.lease_holder.empty(); }))
      << "the service kept the lease";

  // Only the opening force: the closing force stays.
  const auto opening = call_set_forces(2, {parameter("opening_force", kDouble, 72.0)});
  ASSERT_TRUE(opening);
  ASSERT_EQ(opening->results().size(), 1U);
  EXPECT_TRUE(opening->results()[0].successful()) << opening->results()[0].reason();
  EXPECT_TRUE(hand.wait_until(
      [](const HandStatus& s) { return s.closing_force == 50 && s.opening_force == 80; }));
}

TEST_F(Ros2HandServicesTest, ARefusedParameterSetsNothing) {
  set_forces(3);
  auto hand = client_.hand(hand_address(3));
  ASSERT_TRUE(hand.initialize());
  ASSERT_TRUE(hand.set_force(60, 60));
  const std::vector<std::vector<rm::Parameter_>> refused = {
      {parameter("closing_force", kDouble, 45.0), parameter("opening_force", kDouble, 300.0)},
      {parameter("closing_force", kDouble, 10.0)},  // below 20 % of 90 N
      {parameter("closing_force", kString, 45.0)},
      {parameter("grip_force", kDouble, 45.0)},
      {parameter("closing_force", kDouble, std::numeric_limits<double>::quiet_NaN())},
  };
  for (const auto& parameters : refused) {
    const auto reply = call_set_forces(3, parameters);
    ASSERT_TRUE(reply);
    ASSERT_EQ(reply->results().size(), parameters.size());
    for (const auto& result : reply->results()) {
      EXPECT_FALSE(result.successful()) << parameters[0].name();
      EXPECT_FALSE(result.reason().empty());
    }
  }
  EXPECT_EQ(hand.status()->closing_force, 60) << "a refused request changed the force";
  EXPECT_EQ(hand.status()->opening_force, 60);
}

TEST_F(Ros2HandServicesTest, ServicesRefuseWhileAGoalDrivesTheHand) {
  auto& forces = set_forces(3);
  auto hand = client_.hand(hand_address(3));
  ASSERT_TRUE(hand.initialize());
  ASSERT_TRUE(hand.move_to(100));
  ASSERT_TRUE(hand.wait_until([](const HandStatus& s) {
    return s.position == 100 && s.grip != GripState::moving;
  })) << "the hand did not open before the goal";
  auto& gripper = action(3);
  ASSERT_TRUE(gripper.wait_for_server());
  ASSERT_EQ(gripper.send(goal_id(21), 0.0, 0.0), true);
  ASSERT_TRUE(hand.wait_until([](const HandStatus& s) { return s.grip == GripState::moving; }));
  rs::SetParameters_Request_ request;
  request.parameters({parameter("closing_force", kDouble, 45.0)});
  const auto busy = forces.call(request, kClientDeadline);
  ASSERT_TRUE(busy);
  ASSERT_EQ(busy->results().size(), 1U);
  EXPECT_FALSE(busy->results()[0].successful());
  EXPECT_NE(busy->results()[0].reason().find("goal"), std::string::npos)
      << busy->results()[0].reason();
  const auto result = gripper.result(goal_id(21));
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status(), kSucceeded) << "the service disturbed the goal";
  const auto after = forces.call(request, kClientDeadline);
  ASSERT_TRUE(after);
  EXPECT_TRUE(after->results()[0].successful()) << after->results()[0].reason();
}

}  // namespace
}  // namespace dh3::test
