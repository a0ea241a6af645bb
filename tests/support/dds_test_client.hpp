#pragma once
// A minimal raw Fast DDS client of dh3's wire contract for integration tests:
// the IDL types, the topic names and the contract's QoS, nothing of the client
// library. It sends command requests, collects replies (its own), statuses,
// events and service infos, and lets a test wait on any condition over them.
//
//   dh3::test::DdsTestClient client(domain);
//   ASSERT_TRUE(client.wait_for_service("dh3"));
//   auto reply = client.call(client.hand("dh3", "bus0", 1), dh3::msg::MOVE, 60);
//   ASSERT_TRUE(reply);
//   EXPECT_EQ(reply->code(), dh3::msg::OK);

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
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
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <type_traits>
#include <vector>

#include "dh3/contract/dh3.h"
#include "dh3/contract/dh3PubSubTypes.h"
#include "dh3/contract/participant_setup.hpp"
#include "dh3/contract/qos.hpp"
#include "dh3/contract/request_address.hpp"
#include "dh3/contract/type_support.hpp"

namespace dh3::test {

inline constexpr std::chrono::seconds kDdsDeadline{15};
/// How long a test waits for a second reply to a request, which must not come.
inline constexpr std::chrono::milliseconds kDuplicateGrace{1500};

class DdsTestClient {
 public:
  using HandKey = std::tuple<std::string, std::string, std::uint16_t>;

  /// Which replies a client's reply reader asks for.
  enum class Replies {
    all,   ///< the plain reply topic, as a participant of another vendor reads it
    own,   ///< the reply topic filtered to this client_id, as the client library reads it
    none,  ///< no reply reader until read_replies(): a client that never reads its replies
  };

  /// DDS Security credentials in make-test-pki.sh's layout; empty: none.
  struct Credentials {
    std::string dir;
    std::string identity;
  };

  explicit DdsTestClient(int domain, const std::string& name = "dh3-test",
                         Replies replies = Replies::all, const Credentials& credentials = {}) {
    namespace fdds = eprosima::fastdds::dds;
    contract::ParticipantOptions options;
    options.name = name;
    options.domain = domain;
    options.security_dir = credentials.dir;
    options.security_identity = credentials.identity;
    contract::SetupReport report;
    auto created = contract::Participant::create(options, report);
    if (!created) return;
    participant_ = std::move(created).value();
    client_id_ = participant_->client_id();
    const contract::Topics& contract_topics = participant_->topics();
    auto& publisher = participant_->publisher();
    auto& subscriber = participant_->subscriber();
    using contract::TopicRole;
    request_writer_ = publisher.create_datawriter(contract_topics.request,
                                                  contract::writer_qos(TopicRole::request));
    // Refused (nullptr) by DDS Security unless the identity's permissions grant it.
    admin_writer_ = publisher.create_datawriter(contract_topics.admin_request,
                                                contract::writer_qos(TopicRole::request));
    const auto mask = fdds::StatusMask::data_available();
    fdds::TopicDescription* reply_topic = contract_topics.reply;
    if (replies == Replies::own) {
      reply_topic = contract::create_own_replies_topic(participant_->participant(),
                                                       contract_topics.reply, client_id_);
    }
    if (reply_topic != nullptr && replies != Replies::none) {
      subscriber.create_datareader(reply_topic, contract::reader_qos(TopicRole::reply), &listener_,
                                   mask);
    }
    subscriber.create_datareader(contract_topics.status,
                                 contract::reader_qos(TopicRole::hand_status), &listener_, mask);
    subscriber.create_datareader(contract_topics.event, contract::reader_qos(TopicRole::hand_event),
                                 &listener_, mask);
    subscriber.create_datareader(contract_topics.info,
                                 contract::reader_qos(TopicRole::service_info), &listener_, mask);
  }

  /// The participant goes first: its readers call into the members below.
  ~DdsTestClient() { participant_.reset(); }
  DdsTestClient(const DdsTestClient&) = delete;
  DdsTestClient& operator=(const DdsTestClient&) = delete;

  [[nodiscard]] bool ok() const { return participant_ != nullptr && request_writer_ != nullptr; }
  /// The hex GUID prefix of this participant: its client_id in requests.
  [[nodiscard]] const std::string& client_id() const { return client_id_; }

  static msg::HandAddress hand(const std::string& service, const std::string& bus,
                               std::uint16_t can_id) {
    msg::HandAddress address;
    address.service(service);
    address.bus(bus);
    address.can_id(can_id);
    return address;
  }

  /// Sends a request as is (client_id left empty is sent empty); returns its
  /// request_seq, which this client numbers unless `keep_seq`.
  std::uint64_t send(msg::CommandRequest request, bool keep_seq = false) {
    if (!keep_seq) request.request_seq(++last_seq_);
    {
      std::lock_guard lock(mutex_);
      sent_ids_.insert(request.client_id());
    }
    request_writer_->write(&request);
    return request.request_seq();
  }

  /// The participant (hex GUID prefix) that wrote the last reply received.
  [[nodiscard]] std::string last_replier() {
    std::lock_guard lock(mutex_);
    return last_replier_;
  }
  /// Sends a request addressed to the service participant `participant_id`
  /// (contract::addressed_to), as the client library writes them.
  std::uint64_t send_to(msg::CommandRequest request, const std::string& participant_id) {
    request.request_seq(++last_seq_);
    auto address = contract::addressed_to(participant_id);
    request_writer_->write(&request, address);
    return request.request_seq();
  }

  /// This participant may write on the admin request topic.
  [[nodiscard]] bool has_admin_writer() const { return admin_writer_ != nullptr; }
  /// Sends a request on the admin request topic, numbered as send() numbers them.
  std::uint64_t send_admin(msg::CommandRequest request) {
    request.request_seq(++last_seq_);
    admin_writer_->write(&request);
    return request.request_seq();
  }
  /// Waits until an admin request reader (the service's) has matched ours.
  bool wait_admin_reader(std::chrono::milliseconds timeout = kDdsDeadline) {
    return wait_matched(*admin_writer_, timeout);
  }

  /// Waits until every request written so far reached the service's reader
  /// (acknowledged), whether or not it was answered.
  bool wait_delivered(std::chrono::milliseconds timeout = kDdsDeadline) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
    const eprosima::fastrtps::Duration_t wait(static_cast<std::int32_t>(ns / 1'000'000'000),
                                              static_cast<std::uint32_t>(ns % 1'000'000'000));
    return request_writer_->wait_for_acknowledgments(wait) ==
           eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK;
  }

  /// Waits until a request reader (the service's) has matched this client's
  /// writer, for a client that cannot probe with requests (Replies::none).
  bool wait_request_reader(std::chrono::milliseconds timeout = kDdsDeadline) {
    return wait_matched(*request_writer_, timeout);
  }

  /// A client made with Replies::none starts reading the plain reply topic.
  void read_replies() {
    participant_->subscriber().create_datareader(
        participant_->topics().reply, contract::reader_qos(contract::TopicRole::reply), &listener_,
        eprosima::fastdds::dds::StatusMask::data_available());
  }

  /// A request from this client.
  msg::CommandRequest request(const msg::HandAddress& hand, msg::CommandType command,
                              std::int32_t value = 0, std::uint16_t register_code = 0,
                              std::uint32_t timeout_ms = 0) const {
    msg::CommandRequest r;
    r.client_id(client_id_);
    r.hand(hand);
    r.command(command);
    r.value(value);
    r.register_code(register_code);
    r.timeout_ms(timeout_ms);
    return r;
  }

  /// The first reply to `seq` (of `client_id`, this client's by default).
  std::optional<msg::CommandReply> wait_reply(
      std::uint64_t seq, std::chrono::milliseconds timeout = kDdsDeadline,
      const std::optional<std::string>& client_id = std::nullopt) {
    const std::string& who = client_id ? *client_id : client_id_;
    std::optional<msg::CommandReply> found;
    wait_until(
        [&] {
          const auto it = replies_.find({who, seq});
          if (it == replies_.end()) return false;
          found = it->second.front();
          return true;
        },
        timeout);
    return found;
  }

  /// Sends a request and waits for its reply.
  std::optional<msg::CommandReply> call(const msg::HandAddress& hand, msg::CommandType command,
                                        std::int32_t value = 0, std::uint16_t register_code = 0,
                                        std::uint32_t timeout_ms = 0) {
    return wait_reply(send(request(hand, command, value, register_code, timeout_ms)));
  }

  /// How many replies arrived for a request (every request gets exactly one).
  std::size_t reply_count(std::uint64_t seq,
                          const std::optional<std::string>& client_id = std::nullopt) {
    std::lock_guard lock(mutex_);
    const auto it = replies_.find({client_id ? *client_id : client_id_, seq});
    return it == replies_.end() ? 0 : it->second.size();
  }

  /// How many replies arrived carrying `client_id` (any request).
  std::size_t replies_to(const std::string& client_id) {
    std::lock_guard lock(mutex_);
    std::size_t count = 0;
    for (const auto& [key, replies] : replies_) {
      if (key.first == client_id) count += replies.size();
    }
    return count;
  }

  /// Waits until `count` replies carrying `client_id` arrived.
  bool wait_replies_to(const std::string& client_id, std::size_t count,
                       std::chrono::milliseconds timeout = kDdsDeadline) {
    return wait_until(
        [&] {
          std::size_t seen = 0;
          for (const auto& [key, replies] : replies_) {
            if (key.first == client_id) seen += replies.size();
          }
          return seen >= count;
        },
        timeout);
  }

  /// Replies that arrived carrying another client_id than this client's.
  std::size_t foreign_replies() {
    std::lock_guard lock(mutex_);
    std::size_t count = 0;
    for (const auto& [key, replies] : replies_) {
      if (key.first != client_id_) count += replies.size();
    }
    return count;
  }

  /// What this participant's reply filters decided (Replies::own): a rejected
  /// reply reached this process although it was another client's.
  [[nodiscard]] const contract::ReplyFilterCounts& reply_filter_counts() const {
    return participant_->reply_filter_counts();
  }

  /// Every reply that arrived for a request, in arrival order.
  std::vector<msg::CommandReply> replies(
      std::uint64_t seq, const std::optional<std::string>& client_id = std::nullopt) {
    std::lock_guard lock(mutex_);
    const auto it = replies_.find({client_id ? *client_id : client_id_, seq});
    return it == replies_.end() ? std::vector<msg::CommandReply>{} : it->second;
  }

  /// "request 7 of 'ab12...': BUSY (queue full) then TIMEOUT (...)" for a
  /// request's replies, to say what a duplicate was.
  std::string describe_replies(std::uint64_t seq, const std::string& client_id) {
    std::string text = "request " + std::to_string(seq) + " of '" + client_id + "' got";
    for (const auto& reply : replies(seq, client_id)) {
      text +=
          " [code " + std::to_string(static_cast<int>(reply.code())) + ": " + reply.message() + "]";
    }
    return text;
  }

  /// Waits up to `grace` for any request this client sent (under any
  /// client_id) to get a second reply; the first such (client_id,
  /// request_seq), nullopt if none came.
  /// Waiting the whole grace period is the point: a duplicate comes late.
  std::optional<std::pair<std::string, std::uint64_t>> wait_duplicate_reply(
      std::chrono::milliseconds grace) {
    std::optional<std::pair<std::string, std::uint64_t>> duplicate;
    wait_until(
        [&] {
          for (const auto& [key, replies] : replies_) {
            if (replies.size() > 1 && sent_ids_.contains(key.first)) {
              duplicate = key;
              return true;
            }
          }
          return false;
        },
        grace);
    return duplicate;
  }

  /// Waits until the service answers this client: its request reader and reply
  /// writer have both matched ours. Probes with requests the service refuses.
  bool wait_for_service(const std::string& service,
                        std::chrono::milliseconds timeout = kDdsDeadline) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      // An empty bus is always INVALID_ARGUMENT: harmless, and always answered.
      const auto seq = send(request(hand(service, "", 1), msg::READ_REGISTER));
      if (wait_reply(seq, std::chrono::milliseconds(250))) return true;
    }
    return false;
  }

  /// Waits until `pred(latest status of each hand)` holds.
  bool wait_statuses(const std::function<bool(const std::map<HandKey, msg::HandStatus>&)>& pred,
                     std::chrono::milliseconds timeout = kDdsDeadline) {
    return wait_until([&] { return pred(latest_status_); }, timeout);
  }

  /// Waits until the latest status of a hand satisfies `pred`; returns it.
  std::optional<msg::HandStatus> wait_status(
      const msg::HandAddress& hand, const std::function<bool(const msg::HandStatus&)>& pred,
      std::chrono::milliseconds timeout = kDdsDeadline) {
    std::optional<msg::HandStatus> found;
    wait_until(
        [&] {
          const auto it = latest_status_.find({hand.service(), hand.bus(), hand.can_id()});
          if (it == latest_status_.end() || !pred(it->second)) return false;
          found = it->second;
          return true;
        },
        timeout);
    return found;
  }

  /// Waits for an event (received at any time since this client started).
  std::optional<msg::HandEvent> wait_event(const std::function<bool(const msg::HandEvent&)>& pred,
                                           std::chrono::milliseconds timeout = kDdsDeadline) {
    std::optional<msg::HandEvent> found;
    wait_until(
        [&] {
          for (const auto& event : events_) {
            if (pred(event)) {
              found = event;
              return true;
            }
          }
          return false;
        },
        timeout);
    return found;
  }

  std::optional<msg::ServiceInfo> wait_info(
      const std::string& service, const std::function<bool(const msg::ServiceInfo&)>& pred,
      std::chrono::milliseconds timeout = kDdsDeadline) {
    std::optional<msg::ServiceInfo> found;
    wait_until(
        [&] {
          const auto it = infos_.find(service);
          if (it == infos_.end() || !pred(it->second)) return false;
          found = it->second;
          return true;
        },
        timeout);
    return found;
  }

  /// Every status sample received so far, in arrival order.
  std::vector<msg::HandStatus> status_history() {
    std::lock_guard lock(mutex_);
    return status_history_;
  }

  /// Every status sample received so far for one hand, in arrival order.
  std::vector<msg::HandStatus> status_history(const msg::HandAddress& hand) {
    std::lock_guard lock(mutex_);
    std::vector<msg::HandStatus> out;
    for (const auto& s : status_history_) {
      if (s.service() == hand.service() && s.bus() == hand.bus() && s.can_id() == hand.can_id()) {
        out.push_back(s);
      }
    }
    return out;
  }

  std::vector<msg::HandEvent> events() {
    std::lock_guard lock(mutex_);
    return events_;
  }

 private:
  class Listener final : public eprosima::fastdds::dds::DataReaderListener {
   public:
    explicit Listener(DdsTestClient& client) : client_(client) {}
    void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
      const std::string type = reader->type().get_type_name();
      if (type == msg::CommandReplyPubSubType().getName()) {
        take<msg::CommandReply>(reader, [this](msg::CommandReply& r) {
          client_.replies_[{r.client_id(), r.request_seq()}].push_back(std::move(r));
        });
      } else if (type == msg::HandStatusPubSubType().getName()) {
        take<msg::HandStatus>(reader, [this](msg::HandStatus& s) {
          client_.latest_status_[{s.service(), s.bus(), s.can_id()}] = s;
          client_.status_history_.push_back(std::move(s));
        });
      } else if (type == msg::HandEventPubSubType().getName()) {
        take<msg::HandEvent>(
            reader, [this](msg::HandEvent& e) { client_.events_.push_back(std::move(e)); });
      } else if (type == msg::ServiceInfoPubSubType().getName()) {
        take<msg::ServiceInfo>(
            reader, [this](msg::ServiceInfo& i) { client_.infos_[i.service()] = std::move(i); });
      }
    }

   private:
    template <typename T, typename Store>
    void take(eprosima::fastdds::dds::DataReader* reader, Store store) {
      T sample;
      eprosima::fastdds::dds::SampleInfo info;
      while (reader->take_next_sample(&sample, &info) ==
             eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
        if (!info.valid_data) continue;
        {
          std::lock_guard lock(client_.mutex_);
          if constexpr (std::is_same_v<T, msg::CommandReply>) {
            client_.last_replier_ = contract::client_id_for(info.publication_handle);
          }
          store(sample);
        }
        client_.changed_.notify_all();
      }
    }
    DdsTestClient& client_;
  };

  template <typename Pred>
  bool wait_until(Pred pred, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, pred);
  }

  /// Polls until `writer` has matched a reader.
  static bool wait_matched(eprosima::fastdds::dds::DataWriter& writer,
                           std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    eprosima::fastdds::dds::PublicationMatchedStatus status;
    while (std::chrono::steady_clock::now() < deadline) {
      writer.get_publication_matched_status(status);
      if (status.current_count > 0) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  std::unique_ptr<contract::Participant> participant_;
  eprosima::fastdds::dds::DataWriter* request_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* admin_writer_ = nullptr;
  Listener listener_{*this};
  std::string client_id_;
  std::uint64_t last_seq_ = 0;

  std::mutex mutex_;
  std::string last_replier_;
  std::condition_variable changed_;
  std::map<std::pair<std::string, std::uint64_t>, std::vector<msg::CommandReply>> replies_;
  std::set<std::string> sent_ids_;  ///< every client_id this client sent requests under
  std::map<HandKey, msg::HandStatus> latest_status_;
  std::vector<msg::HandStatus> status_history_;
  std::vector<msg::HandEvent> events_;
  std::map<std::string, msg::ServiceInfo> infos_;
};

}  // namespace dh3::test
