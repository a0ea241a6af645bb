#include "ros_participant.hpp"

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/topic/Topic.hpp>

#include "dh3/contract/participant_setup.hpp"

namespace dh3::ros2 {

namespace fdds = eprosima::fastdds::dds;

namespace {

/// rmw_fastrtps's participant USER_DATA, NUL included: a participant without
/// "enclave=" stays out of ROS 2's graph of participants (its endpoints are
/// still seen).
void announce_enclave(fdds::DomainParticipantQos& qos) {
  const std::string text = "enclave=/;";
  std::vector<eprosima::fastrtps::rtps::octet> bytes(text.begin(), text.end());
  bytes.push_back(0);
  qos.user_data().data_vec(bytes);
}

/// `qos` (a writer's or a reader's default) with the ROS 2 profile of `kind`.
template <typename Qos>
Qos with_profile(Qos qos, RosQos kind) {
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  if (kind == RosQos::action_status) {
    qos.durability().kind = fdds::TRANSIENT_LOCAL_DURABILITY_QOS;
    qos.history().depth = 1;
  } else {
    qos.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
    qos.history().depth = 10;
  }
  return qos;
}

}  // namespace

Result<std::unique_ptr<RosParticipant>, std::string> RosParticipant::create(
    const contract::ParticipantOptions& options) {
  contract::SetupReport report;
  auto qos = contract::make_participant_qos(options, report);
  if (!qos) return fail(qos.error());
  announce_enclave(*qos);
  auto* participant = fdds::DomainParticipantFactory::get_instance()->create_participant(
      static_cast<fdds::DomainId_t>(options.domain), *qos);
  if (participant == nullptr) {
    return fail("Fast DDS could not create the ROS 2 participant on domain " +
                std::to_string(options.domain));
  }
  std::unique_ptr<RosParticipant> made(new RosParticipant(participant));
  if (made->publisher_ == nullptr || made->subscriber_ == nullptr) {
    return fail(std::string("Fast DDS could not create the ROS 2 publisher or subscriber"));
  }
  return made;
}

RosParticipant::RosParticipant(fdds::DomainParticipant* participant)
    : participant_(participant),
      publisher_(participant->create_publisher(fdds::PUBLISHER_QOS_DEFAULT)),
      subscriber_(participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT)) {}

RosParticipant::~RosParticipant() {
  participant_->delete_contained_entities();
  fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

fdds::Topic* RosParticipant::topic(const std::string& name, fdds::TypeSupport type) {
  std::lock_guard lock(mutex_);
  if (participant_->find_type(type.get_type_name()).empty()) type.register_type(participant_);
  if (auto* found = dynamic_cast<fdds::Topic*>(participant_->lookup_topicdescription(name))) {
    return found;
  }
  return participant_->create_topic(name, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
}

fdds::DataWriter* RosParticipant::writer(const std::string& topic_name, fdds::TypeSupport type,
                                         RosQos qos, fdds::DataWriterListener* listener) {
  auto* on = topic(topic_name, type);
  if (on == nullptr) return nullptr;
  auto* writer = publisher_->create_datawriter(
      on, with_profile(publisher_->get_default_datawriter_qos(), qos), listener);
  if (writer != nullptr) {
    std::lock_guard lock(mutex_);
    writers_.push_back(writer->guid());
  }
  return writer;
}

fdds::DataReader* RosParticipant::reader(const std::string& topic_name, fdds::TypeSupport type,
                                         RosQos qos, fdds::DataReaderListener* listener) {
  auto* on = topic(topic_name, type);
  if (on == nullptr) return nullptr;
  auto* reader = subscriber_->create_datareader(
      on, with_profile(subscriber_->get_default_datareader_qos(), qos), listener);
  if (reader != nullptr) {
    std::lock_guard lock(mutex_);
    readers_.push_back(reader->guid());
  }
  return reader;
}

eprosima::fastrtps::rtps::GUID_t RosParticipant::guid() const {
  return participant_->guid();
}

std::vector<eprosima::fastrtps::rtps::GUID_t> RosParticipant::readers() const {
  std::lock_guard lock(mutex_);
  return readers_;
}

std::vector<eprosima::fastrtps::rtps::GUID_t> RosParticipant::writers() const {
  std::lock_guard lock(mutex_);
  return writers_;
}

}  // namespace dh3::ros2
