#pragma once
// A stand-in for dh3-service on the wire, for testing the client library
// without the service: a raw Fast DDS participant, named as dh3-service names
// its own ("dh3-service <name>"), that publishes a service info and hand
// statuses, and answers each command request with whatever replies the test's
// handler returns (none, several, other clients' ids...). It can also publish
// events. Deleting it takes its participant off the domain, as a stopped
// service does.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "dh3/contract/dh3.h"
#include "dh3/contract/dh3PubSubTypes.h"
#include "dh3/contract/participant_setup.hpp"
#include "dh3/contract/qos.hpp"
#include "dh3/contract/type_support.hpp"

namespace dh3::test {

/// The reply dh3-service would send to `request`: its ids echoed, code OK,
/// value echoed.
inline msg::CommandReply reply_to(const msg::CommandRequest& request,
                                  msg::ResultCode code = msg::OK) {
  msg::CommandReply reply;
  reply.client_id(request.client_id());
  reply.request_seq(request.request_seq());
  reply.hand(request.hand());
  reply.command(request.command());
  reply.code(code);
  reply.value(request.value());
  return reply;
}

class FakeService {
 public:
  using Handler = std::function<std::vector<msg::CommandReply>(const msg::CommandRequest&)>;

  /// A service `name` with hands `ids` on bus "bus0"; answers every request
  /// OK until set_handler() says otherwise. With `security_dir` it uses DDS
  /// Security with that directory's "service" identity (make-test-pki.sh).
  FakeService(int domain, std::string name, std::vector<std::uint16_t> ids = {1, 2},
              const std::string& security_dir = {})
      : name_(std::move(name)), ids_(std::move(ids)) {
    handler_ = [](const msg::CommandRequest& r) { return std::vector{reply_to(r)}; };
    namespace fdds = eprosima::fastdds::dds;
    contract::ParticipantOptions options;
    options.name = "dh3-service " + name_;
    options.domain = domain;
    options.security_dir = security_dir;
    options.security_identity = "service";
    contract::SetupReport report;
    auto created = contract::Participant::create(options, report);
    if (!created) return;
    participant_ = std::move(created).value();
    const contract::Topics& contract_topics = participant_->topics();
    auto* publisher = &participant_->publisher();
    auto* subscriber = &participant_->subscriber();
    using contract::TopicRole;
    status_writer_ = publisher->create_datawriter(contract_topics.status,
                                                  contract::writer_qos(TopicRole::hand_status));
    event_writer_ = publisher->create_datawriter(contract_topics.event,
                                                 contract::writer_qos(TopicRole::hand_event));
    info_writer_ = publisher->create_datawriter(contract_topics.info,
                                                contract::writer_qos(TopicRole::service_info));
    reply_writer_ =
        publisher->create_datawriter(contract_topics.reply, contract::writer_qos(TopicRole::reply),
                                     &reply_matches_, fdds::StatusMask::publication_matched());

    msg::ServiceInfo service_info;
    service_info.service(name_);
    service_info.version("fake");
    service_info.host("test");
    // A later instance says it started later: that is how clients tell a
    // restart from an old instance still around.
    service_info.started_ns(
        static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                       std::chrono::system_clock::now().time_since_epoch())
                                       .count()));
    msg::BusInfo bus;
    bus.name("bus0");
    bus.spec("sim");
    bus.link_up(true);
    for (const auto id : ids_) {
      msg::HandInfo hand;
      hand.can_id(id);
      hand.name("hand" + std::to_string(id));
      bus.hands().push_back(hand);
    }
    service_info.buses().push_back(bus);
    info_writer_->write(&service_info);
    for (const auto id : ids_) publish_status(id, true);

    // Last, as dh3-service does: requests are taken once everything runs.
    subscriber->create_datareader(contract_topics.request, contract::reader_qos(TopicRole::request),
                                  &listener_, fdds::StatusMask::data_available());
  }

  /// The participant goes first: its reader calls into the members below.
  ~FakeService() { participant_.reset(); }
  FakeService(const FakeService&) = delete;
  FakeService& operator=(const FakeService&) = delete;

  [[nodiscard]] bool ok() const { return participant_ != nullptr && reply_writer_ != nullptr; }
  [[nodiscard]] const std::string& name() const { return name_; }

  void set_handler(Handler handler) {
    std::lock_guard lock(mutex_);
    handler_ = std::move(handler);
  }

  /// A status sample of hand `id` with the next update_seq, not published.
  msg::HandStatus make_status(std::uint16_t id, bool online, std::int32_t position = 100) {
    msg::HandStatus status;
    status.service(name_);
    status.bus("bus0");
    status.can_id(id);
    status.name("hand" + std::to_string(id));
    status.online(online);
    status.position(position);
    status.update_seq(++update_seq_);
    return status;
  }
  void publish(msg::HandStatus status) { status_writer_->write(&status); }
  void publish_status(std::uint16_t id, bool online, std::int32_t position = 100) {
    publish(make_status(id, online, position));
  }

  void publish_event(std::uint16_t id, msg::EventKind kind, std::int32_t value = 0) {
    msg::HandEvent event;
    event.hand().service(name_);
    event.hand().bus("bus0");
    event.hand().can_id(id);
    event.kind(kind);
    event.value(value);
    event.event_seq(++event_seq_);
    event_writer_->write(&event);
  }

  /// Sends a reply of the test's making (not in answer to anything).
  void send_reply(msg::CommandReply reply) { reply_writer_->write(&reply); }

  /// Waits until `count` requests arrived; all received so far.
  std::vector<msg::CommandRequest> wait_requests(std::size_t count,
                                                 std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return requests_.size() >= count; });
    return requests_;
  }

 private:
  class Listener final : public eprosima::fastdds::dds::DataReaderListener {
   public:
    explicit Listener(FakeService& fake) : fake_(fake) {}
    void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
      msg::CommandRequest request;
      eprosima::fastdds::dds::SampleInfo info;
      while (reader->take_next_sample(&request, &info) ==
             eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
        if (!info.valid_data || request.hand().service() != fake_.name_) continue;
        std::vector<msg::CommandReply> replies;
        {
          std::lock_guard lock(fake_.mutex_);
          fake_.requests_.push_back(request);
          replies = fake_.handler_(request);
        }
        fake_.changed_.notify_all();
        fake_.reply_matches_.send_when_matched(*fake_.reply_writer_, request.client_id(),
                                               std::move(replies));
      }
    }

   private:
    FakeService& fake_;
  };

  /// The participants whose reply readers the reply writer has matched. As
  /// dh3-service's ReplyGate does, the replies to a request wait for its
  /// client's reader: dh3's client reads replies VOLATILE, so a reply written
  /// before the writer matched it would be lost, and the client may see its
  /// reader matched well before the writer here does. They are held, and
  /// written by the writer's listener when the match comes, never by blocking
  /// the request listener: client and fake share one process, so Fast DDS
  /// hands them data on each other's threads, and a request listener that
  /// waited for the match held back the discovery that brings it (a NO_REPLY
  /// in ClientTest.ACallMadeBeforeTheServiceAppearsGoesOutOnceItIsReady when
  /// the wait was a bounded 10 s).
  class ReplyMatches final : public eprosima::fastdds::dds::DataWriterListener {
   public:
    void on_publication_matched(
        eprosima::fastdds::dds::DataWriter* writer,
        const eprosima::fastdds::dds::PublicationMatchedStatus& status) override {
      const std::string prefix = contract::client_id_for(
          eprosima::fastrtps::rtps::iHandle2GUID(status.last_subscription_handle).guidPrefix);
      std::vector<msg::CommandReply> released;
      {
        std::lock_guard lock(mutex_);
        if (status.current_count_change > 0) {
          prefixes_.insert(prefix);
          if (auto held = held_.find(prefix); held != held_.end()) {
            released = std::move(held->second);
            held_.erase(held);
          }
        } else if (auto it = prefixes_.find(prefix); it != prefixes_.end()) {
          prefixes_.erase(it);
        }
      }
      for (auto& reply : released) writer->write(&reply);
    }
    /// Writes `replies` now if `client_id`'s reader has matched, else when it does.
    void send_when_matched(eprosima::fastdds::dds::DataWriter& writer, const std::string& client_id,
                           std::vector<msg::CommandReply> replies) {
      {
        std::lock_guard lock(mutex_);
        if (prefixes_.count(client_id) == 0) {
          auto& held = held_[client_id];
          held.insert(held.end(), replies.begin(), replies.end());
          return;
        }
      }
      for (auto& reply : replies) writer.write(&reply);
    }

   private:
    std::mutex mutex_;
    std::multiset<std::string> prefixes_;
    std::map<std::string, std::vector<msg::CommandReply>> held_;  ///< by client_id
  };

  std::string name_;
  std::vector<std::uint16_t> ids_;
  ReplyMatches reply_matches_;  ///< before participant_: its writer calls it
  std::unique_ptr<contract::Participant> participant_;
  eprosima::fastdds::dds::DataWriter* status_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* event_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* info_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* reply_writer_ = nullptr;
  Listener listener_{*this};
  std::atomic<std::uint64_t> update_seq_{0};  // handlers run on a DDS thread
  std::uint64_t event_seq_ = 0;

  std::mutex mutex_;
  std::condition_variable changed_;
  Handler handler_;
  std::vector<msg::CommandRequest> requests_;
};

}  // namespace dh3::test
