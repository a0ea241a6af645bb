#pragma once
// One ROS 2 service served the way rmw_fastrtps serves it: requests on
// "rq/<name>Request", replies on "rr/<name>Reply", a reply correlated to its
// request by the sample identity (WriteParams::related_sample_identity), which
// rmw_fastrtps clients filter on. A request's id is its related writer GUID
// (the client's reply reader, which rmw_fastrtps clients send) or, when that
// is unknown, its writer's GUID, with the request's sequence number.
// `on_request` runs on a Fast DDS listener thread and must not block; reply()
// may be called from any thread.

#include <fastdds/rtps/common/InstanceHandle.h>
#include <fastdds/rtps/common/WriteParams.h>

#include <algorithm>
#include <chrono>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "ros_participant.hpp"

namespace dh3::ros2 {

using RequestId = eprosima::fastrtps::rtps::SampleIdentity;

template <typename Request, typename RequestType, typename Reply, typename ReplyType>
class RosServiceServer : private eprosima::fastdds::dds::DataReaderListener {
 public:
  using Handler = std::function<void(const Request&, const RequestId&)>;

  /// `service` is the fully qualified ROS name ("/a/_action/send_goal").
  /// ok() says whether both endpoints exist.
  RosServiceServer(RosParticipant& participant, const std::string& service, Handler on_request)
      : on_request_(std::move(on_request)) {
    writer_ =
        participant.writer("rr" + service + "Reply",
                           eprosima::fastdds::dds::TypeSupport(new ReplyType()), RosQos::standard);
    reader_ = participant.reader("rq" + service + "Request",
                                 eprosima::fastdds::dds::TypeSupport(new RequestType()),
                                 RosQos::standard, this);
  }
  ~RosServiceServer() override {
    if (reader_ != nullptr) reader_->set_listener(nullptr);
  }
  RosServiceServer(const RosServiceServer&) = delete;
  RosServiceServer& operator=(const RosServiceServer&) = delete;

  [[nodiscard]] bool ok() const { return writer_ != nullptr && reader_ != nullptr; }

  /// Writes the reply to request `id`. Like rmw_fastrtps, it first waits a
  /// while for the reply writer to match the client's reply reader, so a
  /// client that just appeared does not miss it: the client sees its own
  /// endpoints matched before this side may, and on a loaded machine a
  /// one-second wait left a goal unanswered.
  bool reply(const RequestId& id, Reply reply) {
    wait_for_reader(id.writer_guid());
    eprosima::fastrtps::rtps::WriteParams params;
    params.related_sample_identity(id);
    return writer_->write(&reply, params);
  }

 private:
  static constexpr auto kMatchWait = std::chrono::milliseconds(3000);
  static constexpr auto kMatchPoll = std::chrono::milliseconds(5);

  void wait_for_reader(const eprosima::fastrtps::rtps::GUID_t& reader) {
    // The entity kind's reader bit: the id names the client's reply reader.
    if ((reader.entityId.value[3] & 0x04) == 0) return;
    const eprosima::fastrtps::rtps::InstanceHandle_t handle(reader);
    const auto deadline = std::chrono::steady_clock::now() + kMatchWait;
    std::vector<eprosima::fastrtps::rtps::InstanceHandle_t> matched;
    while (std::chrono::steady_clock::now() < deadline) {
      matched.clear();
      writer_->get_matched_subscriptions(matched);
      if (std::find(matched.begin(), matched.end(), handle) != matched.end()) return;
      std::this_thread::sleep_for(kMatchPoll);
    }
  }

  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    Request request;
    eprosima::fastdds::dds::SampleInfo info;
    while (reader->take_next_sample(&request, &info) ==
           eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      RequestId id;
      id.writer_guid(info.related_sample_identity.writer_guid() !=
                             eprosima::fastrtps::rtps::GUID_t::unknown()
                         ? info.related_sample_identity.writer_guid()
                         : info.sample_identity.writer_guid());
      id.sequence_number(info.sample_identity.sequence_number());
      on_request_(request, id);
    }
  }

  Handler on_request_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
};

}  // namespace dh3::ros2
