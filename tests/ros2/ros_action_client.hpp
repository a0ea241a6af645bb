#pragma once
// A ROS 2 action client written from rmw_fastrtps's and rcl_action's
// conventions, not from dh3-ros2's code: each service is a request writer on
// "rq/<service>Request" and a reply reader on "rr/<service>Reply"; a request
// is written with WriteParams::related_sample_identity's writer GUID set to
// the client's reply reader, and a reply is the client's only when its
// SampleInfo::related_sample_identity is (that reader, the request's sequence
// number). Feedback and status are topics under "<action>/_action/".

#include <fastdds/rtps/common/WriteParams.h>

#include <chrono>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <optional>
#include <string>
#include <thread>

#include "ros_participant.hpp"

namespace dh3::test {

using RetCode = eprosima::fastrtps::types::ReturnCode_t;

template <typename Request, typename RequestType, typename Reply, typename ReplyType>
class RosServiceClient {
 public:
  RosServiceClient(ros2::RosParticipant& participant, const std::string& service) {
    writer_ = participant.writer("rq" + service + "Request",
                                 eprosima::fastdds::dds::TypeSupport(new RequestType()),
                                 ros2::RosQos::standard);
    reader_ = participant.reader("rr" + service + "Reply",
                                 eprosima::fastdds::dds::TypeSupport(new ReplyType()),
                                 ros2::RosQos::standard, nullptr);
  }

  /// Both endpoints matched a server's (rclcpp's service_is_ready).
  [[nodiscard]] bool ready() const {
    eprosima::fastdds::dds::PublicationMatchedStatus written;
    eprosima::fastdds::dds::SubscriptionMatchedStatus read;
    return writer_ != nullptr && reader_ != nullptr &&
           writer_->get_publication_matched_status(written) == RetCode::RETCODE_OK &&
           reader_->get_subscription_matched_status(read) == RetCode::RETCODE_OK &&
           written.current_count > 0 && read.current_count > 0;
  }

  /// The reply to `request`, nullopt if none came in time.
  std::optional<Reply> call(Request request, std::chrono::milliseconds timeout) {
    eprosima::fastrtps::rtps::WriteParams params;
    params.related_sample_identity().writer_guid(reader_->guid());
    if (!writer_->write(&request, params)) return std::nullopt;
    const auto sent = params.sample_identity();
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (!reader_->wait_for_unread_message(eprosima::fastrtps::Duration_t(0, 100'000'000))) {
        continue;
      }
      Reply reply;
      eprosima::fastdds::dds::SampleInfo info;
      while (reader_->take_next_sample(&reply, &info) == RetCode::RETCODE_OK) {
        if (!info.valid_data) continue;
        if (info.related_sample_identity.writer_guid() == reader_->guid() &&
            info.related_sample_identity.sequence_number() == sent.sequence_number()) {
          return reply;
        }
        ++foreign_;
      }
    }
    return std::nullopt;
  }

  /// Replies that reached this client for other requests and were dropped.
  [[nodiscard]] int foreign() const { return foreign_; }

 private:
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  int foreign_ = 0;
};

/// Takes samples of `reader` until `pred` accepts one or the deadline passes.
template <typename Message, typename Pred>
std::optional<Message> wait_for_sample(eprosima::fastdds::dds::DataReader* reader, Pred pred,
                                       std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (!reader->wait_for_unread_message(eprosima::fastrtps::Duration_t(0, 100'000'000))) continue;
    Message message;
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&message, &info) == RetCode::RETCODE_OK) {
      if (info.valid_data && pred(message)) return message;
    }
  }
  return std::nullopt;
}

}  // namespace dh3::test
