#pragma once
// DDS wiring of the client: its participant, readers and writers, and the
// listeners that hand every sample and match to ClientCore (which records
// them; the listeners never write to DDS).

#include <fastdds/rtps/common/InstanceHandle.h>

#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "client_core.hpp"
#include "dh3_participant_setup.hpp"

namespace dh3::detail {

namespace fdds = eprosima::fastdds::dds;
namespace frtps = eprosima::fastrtps::rtps;

/// The client's readers and writers, as EndpointCreator is asked for them.
enum class ClientEndpoint {
  request_writer,
  reply_reader,
  status_reader,
  event_reader,
  info_reader,
  group_request_writer,
  group_reply_reader
};

/// Creates the client's readers and writers. DDS Security's access control
/// refuses an endpoint by failing its creation (nullptr): a refused command
/// endpoint makes a read-only client, not a failure. Tests derive from it to
/// be refused without credentials (tests/unit/client/refusing_endpoints.hpp).
class EndpointCreator {
 public:
  EndpointCreator() = default;
  virtual ~EndpointCreator() = default;
  EndpointCreator(const EndpointCreator&) = delete;
  EndpointCreator& operator=(const EndpointCreator&) = delete;

  /// Whether a refused endpoint may be access control's doing.
  [[nodiscard]] virtual bool access_control(const contract::Participant& participant) const {
    return participant.access_control();
  }
  [[nodiscard]] virtual fdds::DataWriter* create_writer(ClientEndpoint /*which*/,
                                                        fdds::Publisher& publisher,
                                                        fdds::Topic* topic,
                                                        const fdds::DataWriterQos& qos,
                                                        fdds::DataWriterListener* listener,
                                                        const fdds::StatusMask& mask) const {
    return publisher.create_datawriter(topic, qos, listener, mask);
  }
  [[nodiscard]] virtual fdds::DataReader* create_reader(ClientEndpoint /*which*/,
                                                        fdds::Subscriber& subscriber,
                                                        fdds::TopicDescription* topic,
                                                        const fdds::DataReaderQos& qos,
                                                        fdds::DataReaderListener* listener,
                                                        const fdds::StatusMask& mask) const {
    return subscriber.create_datareader(topic, qos, listener, mask);
  }
};

/// A participant's GUID prefix in hex, as client_id_for() spells it.
inline std::string prefix_of(const fdds::InstanceHandle_t& handle) {
  return contract::client_id_for(frtps::iHandle2GUID(handle).guidPrefix);
}

struct ClientCore::Dds {
  class ParticipantListener final : public fdds::DomainParticipantListener {
   public:
    explicit ParticipantListener(ClientCore& core) : core_(core) {}
    void on_participant_discovery(fdds::DomainParticipant* /*participant*/,
                                  frtps::ParticipantDiscoveryInfo&& info) override {
      const OnDdsListener on_listener;
      using Status = frtps::ParticipantDiscoveryInfo;
      const std::string prefix = contract::client_id_for(info.info.m_guid.guidPrefix);
      if (info.status == Status::DISCOVERED_PARTICIPANT) {
        core_.on_participant_found(prefix, info.info.m_participantName.to_string());
      } else if (info.status == Status::REMOVED_PARTICIPANT ||
                 info.status == Status::DROPPED_PARTICIPANT) {
        core_.on_participant_left(prefix);
      }
    }

   private:
    ClientCore& core_;
  };

  class RequestWriterListener final : public fdds::DataWriterListener {
   public:
    explicit RequestWriterListener(ClientCore& core) : core_(core) {}
    void on_publication_matched(fdds::DataWriter* /*writer*/,
                                const fdds::PublicationMatchedStatus& status) override {
      const OnDdsListener on_listener;
      core_.on_request_reader_matched(prefix_of(status.last_subscription_handle),
                                      status.current_count_change > 0);
    }

   private:
    ClientCore& core_;
  };

  class GroupRequestWriterListener final : public fdds::DataWriterListener {
   public:
    explicit GroupRequestWriterListener(ClientCore& core) : core_(core) {}
    void on_publication_matched(fdds::DataWriter* /*writer*/,
                                const fdds::PublicationMatchedStatus& status) override {
      const OnDdsListener on_listener;
      core_.on_group_request_reader_matched(prefix_of(status.last_subscription_handle),
                                            status.current_count_change > 0);
    }

   private:
    ClientCore& core_;
  };

  /// One listener for every reader. It tells them apart by topic name, not by
  /// the reader pointers: a reader's first callbacks (transient-local data,
  /// matches) may come before create_datareader() has returned its pointer.
  class ReaderListener final : public fdds::DataReaderListener {
   public:
    explicit ReaderListener(ClientCore& core) : core_(core) {}
    void on_data_available(fdds::DataReader* reader) override {
      const OnDdsListener on_listener;
      const std::string topic = plain_topic_name(*reader);
      if (topic == own_replies_topic_ || topic == topics::COMMAND_REPLY) {
        take<msg::CommandReply>(
            reader, [this](const msg::CommandReply& r, const std::string&) { core_.on_reply(r); });
      } else if (topic == topics::HAND_STATUS) {
        take<msg::HandStatus>(reader, [this](const msg::HandStatus& s, const std::string& from) {
          core_.on_status(from, s);
        });
      } else if (topic == topics::HAND_EVENT) {
        take<msg::HandEvent>(reader, [this](const msg::HandEvent& e, const std::string& from) {
          core_.on_event(from, e);
        });
      } else if (topic == topics::GROUP_REPLY) {
        take<msg::GroupReply>(
            reader, [this](const msg::GroupReply& r, const std::string&) { core_.on_group_reply(r); });
      } else if (topic == topics::SERVICE_INFO) {
        take<msg::ServiceInfo>(reader, [this](const msg::ServiceInfo& i, const std::string& from) {
          core_.on_info(from, i);
        });
      }
    }
    void on_subscription_matched(fdds::DataReader* reader,
                                 const fdds::SubscriptionMatchedStatus& status) override {
      const OnDdsListener on_listener;
      const std::string topic = plain_topic_name(*reader);
      const bool matched = status.current_count_change > 0;
      if (topic == own_replies_topic_ || topic == topics::COMMAND_REPLY) {
        core_.on_reply_writer_matched(prefix_of(status.last_publication_handle), matched);
      } else if (topic == topics::GROUP_REPLY) {
        core_.on_group_reply_writer_matched(prefix_of(status.last_publication_handle), matched);
      } else if (topic == topics::HAND_EVENT) {
        core_.on_event_writer_matched(prefix_of(status.last_publication_handle), matched);
      }
    }

   private:
    /// The topic a reader reads, without the "/follow" of a follower's
    /// filtered view of it (contract::create_follow_topic).
    static std::string plain_topic_name(fdds::DataReader& reader) {
      constexpr std::string_view kFollow = "/follow";
      std::string name = reader.get_topicdescription()->get_name();
      if (std::string_view(name).ends_with(kFollow)) name.resize(name.size() - kFollow.size());
      return name;
    }
    template <typename T, typename Handle>
    static void take(fdds::DataReader* reader, Handle handle) {
      T sample;
      fdds::SampleInfo info;
      while (reader->take_next_sample(&sample, &info) ==
             eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
        if (info.valid_data) handle(sample, prefix_of(info.publication_handle));
      }
    }
    ClientCore& core_;
    const std::string own_replies_topic_ = contract::own_replies_topic_name();
  };

  explicit Dds(ClientCore& core)
      : participant_listener(core),
        request_listener(core),
        group_request_listener(core),
        reader_listener(core) {}

  Dds(const Dds&) = delete;
  Dds& operator=(const Dds&) = delete;

  /// The request writer and the reply reader (on the reply topic filtered to
  /// `client_id`'s replies); nullptr where refused.
  void create_command_endpoints(const EndpointCreator& creator, const std::string& client_id);
  /// The group request writer and group reply reader; nullptr where refused
  /// (group calls then end DENIED).
  void create_group_endpoints(const EndpointCreator& creator);
  /// The status, event and service info readers, on the topics filtered to
  /// `follow` if given; nullptr where refused.
  void create_watch_endpoints(const EndpointCreator& creator,
                              const std::optional<contract::Follow>& follow);

  ParticipantListener participant_listener;
  RequestWriterListener request_listener;
  GroupRequestWriterListener group_request_listener;
  ReaderListener reader_listener;
  /// After the listeners: deleted (with every reader and writer) before them.
  std::unique_ptr<contract::Participant> participant;
  fdds::DataWriter* request_writer = nullptr;
  fdds::DataReader* reply_reader = nullptr;
  fdds::DataReader* status_reader = nullptr;
  fdds::DataReader* event_reader = nullptr;
  fdds::DataReader* info_reader = nullptr;
  fdds::DataWriter* group_request_writer = nullptr;
  fdds::DataReader* group_reply_reader = nullptr;
};

}  // namespace dh3::detail
