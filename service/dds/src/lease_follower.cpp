#include "lease_follower.hpp"

#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>

#include "dh3/contract/participant.hpp"
#include "dh3/contract/qos.hpp"

namespace dh3::dds {
namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;

Result<std::unique_ptr<LeaseFollower>, std::string> LeaseFollower::create(
    contract::Participant& participant, const std::string& service) {
  fdds::Topic* topic = participant.topics().lease;
  if (topic == nullptr) return fail(std::string("the topic ") + dh3::topics::HAND_LEASE);
  std::unique_ptr<LeaseFollower> follower(new LeaseFollower(participant, service));
  follower->reader_ = participant.subscriber().create_datareader(
      topic, contract::reader_qos(contract::TopicRole::hand_lease), follower.get(),
      fdds::StatusMask::data_available());
  if (follower->reader_ == nullptr) return fail("the reader of " + topic->get_name());
  return follower;
}

LeaseFollower::~LeaseFollower() {
  if (reader_ == nullptr) return;
  reader_->set_listener(nullptr);
  participant_.subscriber().delete_datareader(reader_);
}

std::vector<HandedLease> LeaseFollower::held_by_writer(const std::string& writer) const {
  std::lock_guard lock(mutex_);
  return mirror_.held_by_writer(writer, SystemClock::instance().now());
}

void LeaseFollower::on_data_available(fdds::DataReader* reader) {
  msg::HandLease sample;
  fdds::SampleInfo info;
  while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    const std::string writer = contract::client_id_for(info.publication_handle);
    std::lock_guard lock(mutex_);
    mirror_.received(writer, sample, SystemClock::instance().now());
  }
}

}  // namespace dh3::dds
