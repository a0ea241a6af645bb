#pragma once
// The client's DDS wiring: its participant, readers and writers, and the
// listeners that hand every sample and match to ClientCore.
//
// Thread-safe once set up: writes and counters from any thread (Fast DDS's are);
// its listeners run on Fast DDS threads, call only ClientCore and never write.

#include <cstdint>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "client_core.hpp"
#include "dh3/contract/listened_participant.hpp"
#include "dh3/contract/participant_setup.hpp"
#include "endpoint_creator.hpp"
#include "receive_queues.hpp"

namespace dh3::detail {

/// True on a thread that runs a Fast DDS listener of this library: such a
/// thread does not write requests (ClientCore::call() leaves them to its io thread).
inline thread_local bool t_on_dds_listener = false;

/// Marks the current thread as a DDS listener's while it lives.
class OnDdsListener {
 public:
  OnDdsListener() : was_(t_on_dds_listener) { t_on_dds_listener = true; }
  ~OnDdsListener() { t_on_dds_listener = was_; }
  OnDdsListener(const OnDdsListener&) = delete;
  OnDdsListener& operator=(const OnDdsListener&) = delete;

 private:
  bool was_;
};

class ClientEndpoints {
  // The listeners: each hands what Fast DDS reports to ClientCore.
  /// Tells the core when a service's reader of one request topic matches or leaves.
  class RequestWriterListener final : public fdds::DataWriterListener {
   public:
    RequestWriterListener(ClientCore& core, ServiceTracker::Endpoint reader)
        : core_(core), reader_(reader) {}
    void on_publication_matched(fdds::DataWriter* /*writer*/,
                                const fdds::PublicationMatchedStatus& status) override {
      const OnDdsListener on_listener;
      core_.on_matched(reader_, contract::client_id_for(status.last_subscription_handle),
                       status.current_count_change > 0);
    }

   private:
    ClientCore& core_;
    ServiceTracker::Endpoint reader_;
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
        take<msg::CommandReply>(reader, [this](const msg::CommandReply& r, const std::string& from) {
          core_.on_reply(from, r);
        });
      } else if (topic == topics::HAND_STATUS) {
        take<msg::HandStatus>(reader, [this](const msg::HandStatus& s, const std::string& from) {
          core_.on_status(from, s);
        });
      } else if (topic == topics::HAND_EVENT) {
        take<msg::HandEvent>(reader, [this](const msg::HandEvent& e, const std::string& from) {
          core_.on_event(from, e);
        });
      } else if (topic == topics::GROUP_REPLY) {
        take<msg::GroupReply>(reader, [this](const msg::GroupReply& r, const std::string&) {
          core_.on_group_reply(r);
        });
      } else if (topic == topics::SERVICE_INFO) {
        take<msg::ServiceInfo>(reader, [this](const msg::ServiceInfo& i, const std::string& from) {
          core_.on_info(from, i);
        });
      } else if (topic == topics::SERVICE_OWNER) {
        take<msg::ServiceOwner>(reader, [this](const msg::ServiceOwner& o,
                                               const std::string& from) { core_.on_owner(from, o); });
      }
    }
    /// Only the owner reader asks for it: a service's liveliness.
    void on_liveliness_changed(fdds::DataReader* /*reader*/,
                               const fdds::LivelinessChangedStatus& status) override {
      const OnDdsListener on_listener;
      if (status.alive_count_change == 0) return;
      core_.on_owner_liveliness(contract::client_id_for(status.last_publication_handle),
                                status.alive_count_change);
    }
    void on_subscription_matched(fdds::DataReader* reader,
                                 const fdds::SubscriptionMatchedStatus& status) override {
      const OnDdsListener on_listener;
      const std::string topic = plain_topic_name(*reader);
      const bool matched = status.current_count_change > 0;
      const std::string prefix = contract::client_id_for(status.last_publication_handle);
      using Endpoint = ServiceTracker::Endpoint;
      if (topic == own_replies_topic_ || topic == topics::COMMAND_REPLY) {
        core_.on_matched(Endpoint::reply_writer, prefix, matched);
      } else if (topic == topics::GROUP_REPLY) {
        core_.on_matched(Endpoint::group_reply_writer, prefix, matched);
      } else if (topic == topics::HAND_EVENT) {
        core_.on_matched(Endpoint::event_writer, prefix, matched);
      } else if (topic == topics::SERVICE_OWNER) {
        core_.on_matched(Endpoint::owner_writer, prefix, matched);
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
        if (info.valid_data) handle(sample, contract::client_id_for(info.publication_handle));
      }
    }
    ClientCore& core_;
    const std::string own_replies_topic_ = contract::own_replies_topic_name();
  };

 public:
  explicit ClientEndpoints(ClientCore& core)
      : request_listener_(core, ServiceTracker::Endpoint::request_reader),
        group_request_listener_(core, ServiceTracker::Endpoint::group_request_reader),
        admin_request_listener_(core, ServiceTracker::Endpoint::admin_request_reader),
        reader_listener_(core),
        participant_(peer_callbacks(core)) {}
  ClientEndpoints(const ClientEndpoints&) = delete;
  ClientEndpoints& operator=(const ClientEndpoints&) = delete;

  /// Joins the domain; the participant's listener reports to ClientCore from then on.
  Result<void, std::string> create_participant(const ClientOptions& options);
  /// The participant's client_id (create_participant() succeeded).
  [[nodiscard]] std::string client_id() const { return participant_->client_id(); }
  /// Creates the readers and writers with `creator`; a command endpoint that
  /// access control refused makes a read-only client, not a failure.
  Result<void, std::string> create_endpoints(const EndpointCreator& creator,
                                             const std::string& client_id,
                                             const std::optional<contract::Follow>& follow);
  /// Request writer and reply reader exist (not refused).
  [[nodiscard]] bool can_command() const {
    return request_writer_ != nullptr && reply_reader_ != nullptr;
  }
  /// Admin request writer and reply reader exist: under DDS Security, the
  /// identity's permissions grant the admin request topic.
  [[nodiscard]] bool can_administer() const {
    return admin_request_writer_ != nullptr && reply_reader_ != nullptr;
  }
  [[nodiscard]] bool can_group() const {
    return group_request_writer_ != nullptr && group_reply_reader_ != nullptr;
  }
  [[nodiscard]] bool has_info_reader() const { return info_reader_ != nullptr; }
  [[nodiscard]] bool has_owner_reader() const { return owner_reader_ != nullptr; }
  /// How a lapse's judge looks at this process's receive queues: only a
  /// participant that receives over UDP alone has queues to ask (lapse_judge.hpp).
  [[nodiscard]] std::function<ReceiveState()> receive_looker() const {
    return ReceiveQueues::looker(participant_->receives_over_udp_only());
  }
  /// Why commands end DENIED on a read-only client.
  [[nodiscard]] static std::string denied_message(const ClientOptions& options);
  /// Why administrative commands end DENIED on a client that may command.
  [[nodiscard]] static std::string admin_denied_message(const ClientOptions& options);

  /// On the admin request topic if it is administrative, else on the command
  /// request topic; for the service incarnation `to` only (request_address.hpp).
  bool write(const msg::CommandRequest& request, const std::string& to);
  bool write(msg::GroupRequest& request, const std::string& to);
  /// The services' request readers acknowledged every request written.
  [[nodiscard]] bool requests_acknowledged() const;
  /// Replies to other clients and statuses of what we do not follow that the
  /// content filters dropped before they reached a reader.
  [[nodiscard]] std::uint64_t replies_filtered() const;
  [[nodiscard]] std::uint64_t follow_filtered() const;

 private:
  /// Hands each participant that joins or leaves to the core.
  static contract::PeerDiscoveryListener::Callbacks peer_callbacks(ClientCore& core) {
    return {[&core](const std::string& participant, const std::string& name) {
              const OnDdsListener on_listener;
              core.on_participant_found(participant, name);
            },
            [&core](const std::string& participant, bool /*dropped*/) {
              const OnDdsListener on_listener;
              core.on_participant_left(participant);
            },
            {}};
  }
  void create_command_endpoints(const EndpointCreator& creator, const std::string& client_id,
                                const std::optional<contract::Follow>& follow);
  void create_group_endpoints(const EndpointCreator& creator,
                              const std::optional<contract::Follow>& follow);
  /// Where a follower's endpoints go: its cell's partition (dh3/contract/cell_partition.hpp).
  eprosima::fastdds::dds::Publisher& publisher_for(const std::optional<contract::Follow>& follow);
  eprosima::fastdds::dds::Subscriber& subscriber_for(const std::optional<contract::Follow>& follow);
  void create_watch_endpoints(const EndpointCreator& creator,
                              const std::optional<contract::Follow>& follow);

  RequestWriterListener request_listener_;
  RequestWriterListener group_request_listener_;
  RequestWriterListener admin_request_listener_;
  ReaderListener reader_listener_;
  /// After the listeners: deleted (with every reader and writer) before them.
  contract::ListenedParticipant participant_;
  fdds::DataWriter* request_writer_ = nullptr;
  fdds::DataWriter* admin_request_writer_ = nullptr;
  fdds::DataReader* reply_reader_ = nullptr;
  fdds::DataReader* status_reader_ = nullptr;
  fdds::DataReader* event_reader_ = nullptr;
  fdds::DataReader* info_reader_ = nullptr;
  fdds::DataWriter* group_request_writer_ = nullptr;
  fdds::DataReader* group_reply_reader_ = nullptr;
  fdds::DataReader* owner_reader_ = nullptr;
};

}  // namespace dh3::detail
