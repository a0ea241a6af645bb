#pragma once
// dh3-ros2's participant on the ROS 2 side: a DDS participant that announces
// itself as rmw_fastrtps does (USER_DATA "enclave=/;"), with the transports,
// discovery and security of the dh3 options, and writers and readers with
// ROS 2's QoS profiles. Every method may be called from any thread.

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "dh3/base/result.hpp"
#include "dh3/contract/participant_options.hpp"

namespace dh3::ros2 {

/// ROS 2's QoS profiles (rmw/qos_profiles.h, rcl_action/default_qos.h).
enum class RosQos {
  /// topics and services: RELIABLE, VOLATILE, KEEP_LAST 10
  standard,
  /// an action's status: RELIABLE, TRANSIENT_LOCAL, KEEP_LAST 1
  action_status,
};

class RosParticipant {
 public:
  /// The participant, or why it could not be made.
  static Result<std::unique_ptr<RosParticipant>, std::string> create(
      const contract::ParticipantOptions& options);
  ~RosParticipant();
  RosParticipant(const RosParticipant&) = delete;
  RosParticipant& operator=(const RosParticipant&) = delete;

  /// A writer on DDS topic `topic` of the type `type` (registered on first
  /// use of its name). Null when Fast DDS refuses.
  eprosima::fastdds::dds::DataWriter* writer(
      const std::string& topic, eprosima::fastdds::dds::TypeSupport type, RosQos qos,
      eprosima::fastdds::dds::DataWriterListener* listener = nullptr);
  eprosima::fastdds::dds::DataReader* reader(const std::string& topic,
                                             eprosima::fastdds::dds::TypeSupport type, RosQos qos,
                                             eprosima::fastdds::dds::DataReaderListener* listener);

  /// The participant's GUID, and those of every reader and writer made so far
  /// (for ros_discovery_info).
  [[nodiscard]] eprosima::fastrtps::rtps::GUID_t guid() const;
  [[nodiscard]] std::vector<eprosima::fastrtps::rtps::GUID_t> readers() const;
  [[nodiscard]] std::vector<eprosima::fastrtps::rtps::GUID_t> writers() const;

 private:
  explicit RosParticipant(eprosima::fastdds::dds::DomainParticipant* participant);
  eprosima::fastdds::dds::Topic* topic(const std::string& name,
                                       eprosima::fastdds::dds::TypeSupport type);

  mutable std::mutex mutex_;  // topics, type registration, readers_, writers_
  eprosima::fastdds::dds::DomainParticipant* participant_;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::vector<eprosima::fastrtps::rtps::GUID_t> readers_;
  std::vector<eprosima::fastrtps::rtps::GUID_t> writers_;
};

}  // namespace dh3::ros2
