// ros_discovery_info from dh3-ros2 beside dh3-service on the simulator (three
// hands), read as ROS 2's graph reads it (topic ros_discovery_info, RELIABLE,
// TRANSIENT_LOCAL, depth 1) in the layout of the distribution dh3-ros2 was
// told: its participant's GID, its node, and the GIDs of every endpoint of the
// node, the joint_states writer among them.

#include <gtest/gtest.h>

#include <algorithm>

#include "discovery_info.hpp"
#include "integration/client/client_fixture.hpp"
#include "ros2_interfacesPubSubTypes.h"
#include "ros_action_client.hpp"

namespace dh3::test {
namespace {

using eprosima::fastrtps::rtps::GUID_t;

// Per hand: the readers of send_goal, cancel_goal and get_result of two
// actions, and of initialize and set_forces.
constexpr std::size_t kReadersPerHand = 8;
// Per hand: the reply writers of those, and two actions' feedback and status.
constexpr std::size_t kWritersPerHand = 12;
constexpr std::size_t kHands = 3;

/// rmw's GID of a GUID: prefix, entity id, zero-padded.
template <typename Gid>
bool is_gid_of(const Gid& gid, const GUID_t& guid) {
  const auto& d = gid.data();
  return std::equal(std::begin(guid.guidPrefix.value), std::end(guid.guidPrefix.value),
                    d.begin()) &&
         std::equal(std::begin(guid.entityId.value), std::end(guid.entityId.value),
                    d.begin() + 12) &&
         std::all_of(d.begin() + 16, d.end(), [](auto b) { return b == 0; });
}

class Ros2DiscoveryInfoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(service_.started());
    contract::ParticipantOptions options;
    options.domain = test_domain();
    options.name = "ros2_graph";
    auto made = ros2::RosParticipant::create(options);
    ASSERT_TRUE(made) << made.error();
    participant_ = std::move(made).value();
    ASSERT_TRUE(client_.wait_for_hand(hand_spec(3)));
  }

  void start_ros2(const std::string& distro) {
    ros2_ = std::make_unique<Process>(
        DH3_ROS2_PATH,
        std::vector<std::string>{"--domain", std::to_string(test_domain()), "--ros-distro", distro,
                                 "--namespace", "/cell", "--log-level", "warn"},
        Process::Stdin::dev_null);
    ASSERT_TRUE(ros2_->wait_for_line("dh3-ros2: publishing joint states", kClientDeadline));
  }

  /// The GUID of the writer of a joint state, as its sample carries it.
  std::optional<GUID_t> joint_states_writer() {
    auto* reader = participant_->reader(
        "rt/cell/joint_states",
        eprosima::fastdds::dds::TypeSupport(new sensor_msgs::msg::dds_::JointState_PubSubType()),
        ros2::RosQos::standard, nullptr);
    const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
    while (reader != nullptr && std::chrono::steady_clock::now() < deadline) {
      if (!reader->wait_for_unread_message(eprosima::fastrtps::Duration_t(0, 100'000'000))) {
        continue;
      }
      sensor_msgs::msg::dds_::JointState_ message;
      eprosima::fastdds::dds::SampleInfo info;
      if (reader->take_next_sample(&message, &info) == RetCode::RETCODE_OK && info.valid_data) {
        return info.sample_identity.writer_guid();
      }
    }
    return std::nullopt;
  }

  /// Reads ros_discovery_info in `distro`'s layout until dh3-ros2's node
  /// announces every hand's endpoints; checks it against `writer`.
  template <typename Info>
  void expect_node_of(ros2::RosDistro distro, const GUID_t& writer) {
    auto* reader = participant_->reader("ros_discovery_info", ros2::discovery_info_type(distro),
                                        ros2::RosQos::action_status, nullptr);
    ASSERT_NE(reader, nullptr);
    const auto info = wait_for_sample<Info>(
        reader,
        [](const Info& m) {
          return m.node_entities_info_seq().size() == 1 &&
                 m.node_entities_info_seq()[0].node_name() == "dh3_ros2" &&
                 m.node_entities_info_seq()[0].reader_gid_seq().size() == kHands * kReadersPerHand;
        },
        kClientDeadline);
    ASSERT_TRUE(info) << "no ros_discovery_info with dh3-ros2's node and every hand";
    GUID_t participant = writer;
    participant.entityId = eprosima::fastrtps::rtps::c_EntityId_RTPSParticipant;
    EXPECT_TRUE(is_gid_of(info->gid(), participant)) << "the GID is not the participant's GUID";
    const auto& node = info->node_entities_info_seq()[0];
    EXPECT_EQ(node.node_namespace(), "/cell");
    EXPECT_EQ(node.writer_gid_seq().size(), 1 + kHands * kWritersPerHand);
    EXPECT_TRUE(std::any_of(node.writer_gid_seq().begin(), node.writer_gid_seq().end(),
                            [&](const auto& gid) { return is_gid_of(gid, writer); }))
        << "the joint_states writer is not among the node's writers";
  }

  RunningService service_{sim_config()};
  Client client_{client_options()};
  std::unique_ptr<ros2::RosParticipant> participant_;
  std::unique_ptr<Process> ros2_;
};

TEST_F(Ros2DiscoveryInfoTest, JazzyLayoutNamesTheNodeAndItsEndpoints) {
  start_ros2("jazzy");
  const auto writer = joint_states_writer();
  ASSERT_TRUE(writer) << "no joint state";
  expect_node_of<rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_>(ros2::RosDistro::jazzy,
                                                                      *writer);
}

TEST_F(Ros2DiscoveryInfoTest, HumbleLayoutNamesTheNodeAndItsEndpoints) {
  start_ros2("humble");
  const auto writer = joint_states_writer();
  ASSERT_TRUE(writer) << "no joint state";
  expect_node_of<rmw_dds_common_humble::msg::dds_::ParticipantEntitiesInfo_>(
      ros2::RosDistro::humble, *writer);
}

}  // namespace
}  // namespace dh3::test
