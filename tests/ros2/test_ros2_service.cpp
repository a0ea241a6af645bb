// dh3-ros2 as a ROS 2 user runs it: a child process beside dh3-service on
// the simulator (three hands, hand 1 with an object at 40), read by a peer
// that subscribes as a ROS 2 node would: topic rt/joint_states, type
// sensor_msgs::msg::dds_::JointState_, RELIABLE, VOLATILE, KEEP_LAST 10.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "integration/client/client_fixture.hpp"
#include "ros2_interfacesPubSubTypes.h"
#include "ros_participant.hpp"

namespace dh3::test {
namespace {

using JointState = sensor_msgs::msg::dds_::JointState_;

/// A ROS 2 subscriber of rt/joint_states, written from ROS 2's conventions.
class JointStateReader {
 public:
  JointStateReader() {
    contract::ParticipantOptions options;
    options.domain = test_domain();
    options.name = "ros2_peer";
    auto made = ros2::RosParticipant::create(options);
    if (!made) return;
    participant_ = std::move(made).value();
    reader_ = participant_->reader(
        "rt/joint_states",
        eprosima::fastdds::dds::TypeSupport(new sensor_msgs::msg::dds_::JointState_PubSubType()),
        ros2::RosQos::standard, nullptr);
  }
  [[nodiscard]] bool ready() const { return reader_ != nullptr; }

  /// The first message `pred` accepts, within the deadline.
  std::optional<JointState> wait_for(const std::function<bool(const JointState&)>& pred) {
    const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
    while (std::chrono::steady_clock::now() < deadline) {
      if (!reader_->wait_for_unread_message(eprosima::fastrtps::Duration_t(1, 0))) continue;
      JointState message;
      eprosima::fastdds::dds::SampleInfo info;
      while (reader_->take_next_sample(&message, &info) == ReturnCode_t::RETCODE_OK) {
        if (info.valid_data && pred(message)) return message;
      }
    }
    return std::nullopt;
  }

 private:
  using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;
  std::unique_ptr<ros2::RosParticipant> participant_;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
};

std::string joint(std::uint16_t id, const std::string& which) {
  return test_service_name() + "_bus0_" + std::to_string(id) + "_" + which + "_joint";
}

class Ros2JointStatesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(service_.started());
    ASSERT_TRUE(ros2_.wait_for_line("dh3-ros2: publishing joint states on rt/joint_states",
                                    kClientDeadline));
    ASSERT_TRUE(peer_.ready());
    ASSERT_TRUE(client_.wait_for_hand(hand_spec(3)));
  }

  RunningService service_{sim_config()};
  Process ros2_{DH3_ROS2_PATH,
                {"--domain", std::to_string(test_domain()), "--log-level", "warn"},
                Process::Stdin::dev_null};
  JointStateReader peer_;
  Client client_{client_options()};
};

TEST_F(Ros2JointStatesTest, AMoveShowsAsTheFingerJointsOpeningInMeters) {
  auto hand = client_.hand(hand_address(2));
  ASSERT_TRUE(hand.initialize());
  ASSERT_TRUE(hand.move_to(60));
  ASSERT_TRUE(hand.rotate_to(50));
  const auto seen = peer_.wait_for([](const JointState& m) {
    return m.name().size() == 2 && m.name()[0] == joint(2, "finger") && m.position().size() == 2 &&
           std::abs(m.position()[0] - 0.6 * 0.095) < 1e-9 &&
           std::abs(m.position()[1] - 0.5 * M_PI / 2) < 1e-9;
  });
  ASSERT_TRUE(seen) << "no JointState of hand 2 at 60 % open and 50 % rotated";
  EXPECT_EQ(seen->name()[1], joint(2, "rotation"));
  EXPECT_GT(seen->header().stamp().sec(), 0);
}

TEST_F(Ros2JointStatesTest, AGraspShowsTheGrippingForceInNewtons) {
  auto hand = client_.hand(hand_address(1));
  ASSERT_TRUE(hand.initialize());
  const auto grasp = hand.grasp(60);
  ASSERT_EQ(grasp.grasp, GraspOutcome::grasped) << grasp.message;
  const auto seen = peer_.wait_for([](const JointState& m) {
    return m.name().size() == 2 && m.name()[0] == joint(1, "finger") && m.effort().size() == 2 &&
           std::abs(m.effort()[0] - 0.6 * 90) < 1e-9 && std::abs(m.position()[0] - 0.038) < 0.002;
  });
  // The object is at 40 %: 0.038 m with the default 0.095 m fully open.
  ASSERT_TRUE(seen) << "no JointState of hand 1 holding the object at 0.038 m with 54 N";
}

}  // namespace
}  // namespace dh3::test
