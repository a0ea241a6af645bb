#pragma once
// One ROS 2 service served the way rmw_fastrtps serves it: requests on
// "rq/<name>Request", replies on "rr/<name>Reply", a reply correlated to its
// request by the sample identity (WriteParams::related_sample_identity), which
// rmw_fastrtps clients filter on. A request's id is its related writer GUID
// (the client's reply reader, which rmw_fastrtps clients send) or, when that
// is unknown, its writer's GUID, with the request's sequence number.
// A reply to a client whose reply reader has not matched yet is held until it
// does (HeldReplies), never waited for on the calling thread.
// `on_request` runs on a Fast DDS listener thread and must not block; reply()
// may be called from any thread and does not block.

#include <fastdds/rtps/common/InstanceHandle.h>
#include <fastdds/rtps/common/WriteParams.h>

#include <chrono>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <functional>
#include <string>

#include "held_replies.hpp"
#include "ros_participant.hpp"

namespace dh3::ros2 {

using RequestId = eprosima::fastrtps::rtps::SampleIdentity;

template <typename Request, typename RequestType, typename Reply, typename ReplyType>
class RosServiceServer : private eprosima::fastdds::dds::DataReaderListener,
                         private eprosima::fastdds::dds::DataWriterListener {
 public:
  using Handler = std::function<void(const Request&, const RequestId&)>;

  /// `service` is the fully qualified ROS name ("/a/_action/send_goal").
  /// ok() says whether both endpoints exist.
  RosServiceServer(RosParticipant& participant, const std::string& service, Handler on_request)
      : on_request_(std::move(on_request)) {
    writer_ =
        participant.writer("rr" + service + "Reply",
                           eprosima::fastdds::dds::TypeSupport(new ReplyType()), RosQos::standard,
                           this);
    reader_ = participant.reader("rq" + service + "Request",
                                 eprosima::fastdds::dds::TypeSupport(new RequestType()),
                                 RosQos::standard, this);
  }
  ~RosServiceServer() override {
    if (reader_ != nullptr) reader_->set_listener(nullptr);
    if (writer_ != nullptr) writer_->set_listener(nullptr);
  }
  RosServiceServer(const RosServiceServer&) = delete;
  RosServiceServer& operator=(const RosServiceServer&) = delete;

  [[nodiscard]] bool ok() const { return writer_ != nullptr && reader_ != nullptr; }

  /// Writes the reply to request `id`, at once if the client's reply reader
  /// has matched (or the id names no reader), else once it matches: within
  /// kHoldLimit, after which it is dropped (see HeldReplies).
  void reply(const RequestId& id, Reply reply) {
    const auto& reader = id.writer_guid();
    // The entity kind's reader bit: the id names the client's reply reader.
    if ((reader.entityId.value[3] & 0x04) == 0) {
      write(id, reply);
      return;
    }
    auto write_it = [this, id, reply]() mutable { write(id, reply); };
    if (held_.admit(reader_key(eprosima::fastrtps::rtps::InstanceHandle_t(reader)), write_it,
                    HeldReplies::Clock::now())) {
      write_it();
    }
  }

  /// Replies held now for readers not matched yet.
  [[nodiscard]] std::size_t held_replies() const { return held_.held(); }

 private:
  // As long as a client may take to match after its request: rmw_fastrtps
  // clients match their own endpoints first, and a loaded machine took over
  // a second.
  static constexpr auto kHoldLimit = std::chrono::seconds(10);
  static constexpr std::size_t kHoldCap = 256;

  static std::string reader_key(const eprosima::fastrtps::rtps::InstanceHandle_t& handle) {
    std::string key(16, '\0');
    for (std::size_t i = 0; i < key.size(); ++i) key[i] = static_cast<char>(handle.value[i]);
    return key;
  }

  void write(const RequestId& id, Reply& reply) {
    eprosima::fastrtps::rtps::WriteParams params;
    params.related_sample_identity(id);
    writer_->write(&reply, params);
  }

  void on_publication_matched(
      eprosima::fastdds::dds::DataWriter* /*writer*/,
      const eprosima::fastdds::dds::PublicationMatchedStatus& status) override {
    for (auto& due : held_.reader_matched(reader_key(status.last_subscription_handle),
                                          status.current_count_change > 0,
                                          HeldReplies::Clock::now())) {
      due();
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
  HeldReplies held_{kHoldLimit, kHoldCap};
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
};

}  // namespace dh3::ros2
