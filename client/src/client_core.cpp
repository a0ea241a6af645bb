#include "client_core.hpp"

#include <fastdds/rtps/common/InstanceHandle.h>

#include <algorithm>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "conversions.hpp"
#include "dh3_idl/dh3PubSubTypes.h"
#include "dh3_participant_setup.hpp"
#include "dh3_qos.hpp"

namespace dh3::detail {

namespace fdds = eprosima::fastdds::dds;
namespace frtps = eprosima::fastrtps::rtps;
using eprosima::fastrtps::types::ReturnCode_t;

namespace {

/// The participant name dh3-service gives itself ("dh3-service <name>"): lets
/// the client know a service's participant, and so a restart, before any of
/// its samples arrive. Services of other vendors are still found by their
/// samples; only the early warning is lost.
constexpr std::string_view kServiceParticipantPrefix = "dh3-service ";

std::string prefix_of(const fdds::InstanceHandle_t& handle) {
  return contract::client_id_for(frtps::iHandle2GUID(handle).guidPrefix);
}

Reply make_reply(Code code, std::string message) {
  Reply reply;
  reply.code = code;
  reply.message = std::move(message);
  return reply;
}

/// Runs a user callback; an exception from user code must not end the
/// dispatcher thread (and with it every later callback).
template <typename F>
void run_guarded(F&& f) {
  try {
    f();
  } catch (...) {  // NOLINT(bugprone-empty-catch): the user's exception, nothing to do with it
  }
}

}  // namespace

// ---------------------------------------------------------------------------
// Dispatcher

Dispatcher::Dispatcher() : state_(std::make_shared<State>()) {
  thread_ = std::thread([state = state_] {
    std::unique_lock lock(state->mutex);
    for (;;) {
      state->wake.wait(lock, [&] { return state->stop || !state->tasks.empty(); });
      if (state->stop) return;
      auto task = std::move(state->tasks.front());
      state->tasks.pop_front();
      lock.unlock();
      task();
      lock.lock();
    }
  });
  thread_id_ = thread_.get_id();
}

Dispatcher::~Dispatcher() {
  stop();
}

void Dispatcher::post(std::function<void()> task) {
  {
    std::lock_guard lock(state_->mutex);
    if (state_->stop) return;
    state_->tasks.push_back(std::move(task));
  }
  state_->wake.notify_one();
}

void Dispatcher::stop() {
  {
    std::lock_guard lock(state_->mutex);
    state_->stop = true;
    state_->tasks.clear();
  }
  state_->wake.notify_all();
  if (!thread_.joinable()) return;
  if (on_dispatcher_thread()) {
    thread_.detach();  // the task running now returns into a loop that ends
  } else {
    thread_.join();
  }
}

bool Dispatcher::on_dispatcher_thread() const {
  return std::this_thread::get_id() == thread_id_;
}

// ---------------------------------------------------------------------------
// DDS entities and their listeners

struct ClientCore::Dds {
  class ParticipantListener final : public fdds::DomainParticipantListener {
   public:
    explicit ParticipantListener(ClientCore& core) : core_(core) {}
    void on_participant_discovery(fdds::DomainParticipant* /*participant*/,
                                  frtps::ParticipantDiscoveryInfo&& info) override {
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
      core_.on_request_reader_matched(prefix_of(status.last_subscription_handle),
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
      const std::string& topic = reader->get_topicdescription()->get_name();
      if (topic == topics::COMMAND_REPLY) {
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
      } else if (topic == topics::SERVICE_INFO) {
        take<msg::ServiceInfo>(reader, [this](const msg::ServiceInfo& i, const std::string& from) {
          core_.on_info(from, i);
        });
      }
    }
    void on_subscription_matched(fdds::DataReader* reader,
                                 const fdds::SubscriptionMatchedStatus& status) override {
      const std::string& topic = reader->get_topicdescription()->get_name();
      const bool matched = status.current_count_change > 0;
      if (topic == topics::COMMAND_REPLY) {
        core_.on_reply_writer_matched(prefix_of(status.last_publication_handle), matched);
      } else if (topic == topics::HAND_EVENT) {
        core_.on_event_writer_matched(prefix_of(status.last_publication_handle), matched);
      }
    }

   private:
    template <typename T, typename Handle>
    static void take(fdds::DataReader* reader, Handle handle) {
      T sample;
      fdds::SampleInfo info;
      while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
        if (info.valid_data) handle(sample, prefix_of(info.publication_handle));
      }
    }
    ClientCore& core_;
  };

  explicit Dds(ClientCore& core)
      : participant_listener(core), request_listener(core), reader_listener(core) {}

  Dds(const Dds&) = delete;
  Dds& operator=(const Dds&) = delete;

  ParticipantListener participant_listener;
  RequestWriterListener request_listener;
  ReaderListener reader_listener;
  /// After the listeners: deleted (with every reader and writer) before them.
  std::unique_ptr<contract::Participant> participant;
  fdds::DataWriter* request_writer = nullptr;
  fdds::DataReader* reply_reader = nullptr;
  fdds::DataReader* status_reader = nullptr;
  fdds::DataReader* event_reader = nullptr;
  fdds::DataReader* info_reader = nullptr;
};

bool ClientCore::set_up_dds(std::string& error, const Refusals& simulated) {
  contract::ParticipantOptions participant_options;
  participant_options.name = options_.participant_name;
  participant_options.domain = options_.domain;
  participant_options.interfaces = options_.interfaces;
  participant_options.udp_only = options_.udp_only;
  participant_options.discovery_servers = options_.discovery_servers;
  participant_options.xml_profile_file = options_.xml_profile_file;
  participant_options.xml_profile = options_.xml_profile;
  participant_options.security_dir = options_.security_dir;
  participant_options.security_identity = options_.security_identity;
  dds_->participant =
      std::make_unique<contract::Participant>(participant_options, &dds_->participant_listener);
  if (!dds_->participant->ok()) {
    error = dds_->participant->error();
    return false;
  }
  // With access control, a writer or reader the permissions do not grant
  // fails to be created: for the command endpoints that makes a read-only
  // client, not a failure.
  const bool access_control = dds_->participant->access_control() || simulated.request_writer ||
                              simulated.reply_reader || simulated.info_reader;
  client_id_ = dds_->participant->client_id();

  const contract::Topics& contract_topics = dds_->participant->topics();
  auto* publisher = &dds_->participant->publisher();
  auto* subscriber = &dds_->participant->subscriber();
  using contract::TopicRole;
  const auto data = fdds::StatusMask::data_available();
  auto data_and_matches = fdds::StatusMask::data_available();
  data_and_matches << fdds::StatusMask::subscription_matched();
  // The command endpoints first, each right after the other: the service
  // answers on the reply topic as soon as a request arrives, so our reply
  // reader's announcement should trail the request writer's as little as
  // possible (a reply written before the service knows our reader is lost).
  if (!simulated.request_writer) {
    dds_->request_writer = publisher->create_datawriter(
        contract_topics.request, contract::writer_qos(TopicRole::request), &dds_->request_listener,
        fdds::StatusMask::publication_matched());
  }
  if (!simulated.reply_reader) {
    dds_->reply_reader =
        subscriber->create_datareader(contract_topics.reply, contract::reader_qos(TopicRole::reply),
                                      &dds_->reader_listener, data_and_matches);
  }
  // Every identity must read statuses and events; a refused command endpoint
  // above is a read-only client (below).
  dds_->status_reader = subscriber->create_datareader(contract_topics.status,
                                                      contract::reader_qos(TopicRole::hand_status),
                                                      &dds_->reader_listener, data);
  dds_->event_reader = subscriber->create_datareader(contract_topics.event,
                                                     contract::reader_qos(TopicRole::hand_event),
                                                     &dds_->reader_listener, data_and_matches);
  if (dds_->status_reader == nullptr || dds_->event_reader == nullptr) {
    error = access_control ? "DDS Security: this identity may not read hand statuses and events"
                           : "cannot create the dh3 readers";
    return false;
  }
  if (!simulated.info_reader) {
    dds_->info_reader = subscriber->create_datareader(contract_topics.info,
                                                      contract::reader_qos(TopicRole::service_info),
                                                      &dds_->reader_listener, data);
  }
  const bool complete = dds_->request_writer != nullptr && dds_->reply_reader != nullptr &&
                        dds_->info_reader != nullptr;
  if (!complete && !access_control) {
    error = "cannot create the dh3 readers and writers";
    return false;
  }
  can_command_ = dds_->request_writer != nullptr && dds_->reply_reader != nullptr;
  has_info_reader_ = dds_->info_reader != nullptr;
  if (!can_command_) {
    denied_message_ = "not permitted to publish command requests";
    if (!options_.security_dir.empty()) {
      denied_message_ += " (DDS Security identity '" + options_.security_identity + "')";
    } else {
      denied_message_ += " (DDS Security permissions of this participant)";
    }
  }
  return true;
}

// ---------------------------------------------------------------------------
// Life cycle

ClientCore::ClientCore(ClientOptions options, Refusals simulated) : options_(std::move(options)) {
  dds_ = std::make_unique<Dds>(*this);
  std::string error;
  if (!set_up_dds(error, simulated)) {
    error_ = std::move(error);
    dds_.reset();
    closed_ = true;
    return;
  }
  io_thread_ = std::thread([this] { io_loop(); });
}

ClientCore::~ClientCore() {
  close();
}

bool ClientCore::connected() const {
  std::lock_guard lock(mutex_);
  return !closed_;
}

void ClientCore::close() {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_ && !io_thread_.joinable() && dds_ == nullptr) return;
    closed_ = true;
    for (auto& [seq, pending] : pending_) {
      out.completions.emplace_back(std::move(pending.done),
                                   make_reply(Code::not_connected, "the client was closed"));
    }
    pending_.clear();
    to_write_.clear();
  }
  io_wake_.notify_all();
  changed_.notify_all();
  // The io thread is the only writer: once it is gone no write can race the
  // deletion below.
  if (io_thread_.joinable()) io_thread_.join();
  run(out);
  dds_.reset();  // waits for listener callbacks in progress
  dispatcher_.stop();
}

// ---------------------------------------------------------------------------
// Calls

std::optional<Reply> ClientCore::check(const HandAddress& hand, msg::CommandType command,
                                       std::int32_t value) {
  msg::CommandRequest request;
  request.hand(to_msg(hand));
  request.command(command);
  request.value(value);
  return check_request(request);
}

void ClientCore::call(const HandAddress& hand, msg::CommandType command, std::int32_t value,
                      std::uint16_t register_code, Timeout timeout, Done done) {
  msg::CommandRequest request;
  request.hand(to_msg(hand));
  request.command(command);
  request.value(value);
  request.register_code(register_code);
  if (auto invalid = check_request(request)) {
    done(std::move(*invalid));
    return;
  }
  {
    std::unique_lock lock(mutex_);
    if (closed_) {
      lock.unlock();
      done(make_reply(Code::not_connected, error_.empty() ? "the client was closed" : error_));
      return;
    }
    if (!can_command_) {
      lock.unlock();
      done(make_reply(Code::denied, denied_message_));
      return;
    }
    const std::uint64_t seq = ++last_seq_;
    request.client_id(client_id_);
    request.request_seq(seq);
    Pending pending;
    pending.hand = hand;
    pending.request = std::move(request);
    pending.timeout = effective(timeout);
    pending.deadline = Clock::now() + pending.timeout;
    pending.done = std::move(done);
    if (ready_locked(hand.service)) {
      pending.sent_to = services_.find(hand.service)->second.incarnation;
      to_write_.push_back(seq);
    }
    pending_.emplace(seq, std::move(pending));
    io_kick_ = true;  // its deadline may be the earliest now
  }
  io_wake_.notify_all();
}

std::future<Reply> ClientCore::call(const HandAddress& hand, msg::CommandType command,
                                    std::int32_t value, std::uint16_t register_code,
                                    Timeout timeout) {
  auto promise = std::make_shared<std::promise<Reply>>();
  auto future = promise->get_future();
  call(hand, command, value, register_code, timeout,
       [promise](Reply reply) { promise->set_value(std::move(reply)); });
  return future;
}

void ClientCore::io_loop() {
  std::unique_lock lock(mutex_);
  while (!closed_) {
    // Requests first: a deadline check must not end a call whose request was
    // about to go out.
    while (!to_write_.empty() && !closed_) {
      const std::uint64_t seq = to_write_.front();
      to_write_.pop_front();
      const auto it = pending_.find(seq);
      // Ended meanwhile (service lost, reply, deadline): never send it, so a
      // command the caller was told failed does not run after all.
      if (it == pending_.end()) continue;
      msg::CommandRequest request = it->second.request;
      lock.unlock();
      const bool written = dds_->request_writer->write(&request);
      lock.lock();
      if (!written) {
        if (const auto again = pending_.find(seq); again != pending_.end()) {
          auto done = std::move(again->second.done);
          pending_.erase(again);
          lock.unlock();
          done(make_reply(Code::not_connected, "could not publish the request"));
          lock.lock();
        }
      }
    }
    if (closed_) break;

    const auto now = Clock::now();
    std::vector<std::pair<Done, Reply>> expired;
    auto next = Clock::time_point::max();
    for (auto it = pending_.begin(); it != pending_.end();) {
      if (it->second.deadline <= now) {
        expired.emplace_back(std::move(it->second.done), expired_locked(it->second));
        it = pending_.erase(it);
      } else {
        next = std::min(next, it->second.deadline);
        ++it;
      }
    }
    if (!expired.empty()) {
      lock.unlock();
      for (auto& [done, reply] : expired) done(std::move(reply));
      lock.lock();
      continue;  // state may have changed while unlocked
    }
    io_kick_ = false;
    const auto wake = [this] { return closed_ || io_kick_ || !to_write_.empty(); };
    if (next == Clock::time_point::max()) {
      io_wake_.wait(lock, wake);
    } else {
      io_wake_.wait_until(lock, next, wake);
    }
  }
}

Reply ClientCore::expired_locked(const Pending& pending) const {
  const auto& service = pending.hand.service;
  const std::string what =
      command_name(pending.request.command()) + " for " + pending.hand.to_string();
  const std::string within = " within " + describe_duration(pending.timeout);
  if (!pending.sent_to.empty()) {
    return make_reply(Code::no_reply,
                      "no reply from service '" + service + "' to " + what + within);
  }
  const auto it = services_.find(service);
  if (it != services_.end() && it->second.alive) {
    return make_reply(Code::no_service, "service '" + service +
                                            "' was found but did not become ready to take "
                                            "requests" +
                                            within + " (" + what + " not sent)");
  }
  return make_reply(Code::no_service, "no service '" + service + "' found on DDS domain " +
                                          std::to_string(options_.domain) + within + " (" + what +
                                          " not sent)");
}

void ClientCore::run(Actions& actions) {
  for (auto& [done, reply] : actions.completions) done(std::move(reply));
  actions.completions.clear();
  if (actions.wake_io) io_wake_.notify_all();
}

// ---------------------------------------------------------------------------
// Services and their incarnations

bool ClientCore::ready_locked(const std::string& service) const {
  const auto it = services_.find(service);
  if (it == services_.end() || !it->second.alive || it->second.incarnation.empty()) return false;
  const auto& prefix = it->second.incarnation;
  // Read-only: nothing to send, so ready means its events reach us.
  if (!can_command_) return event_writers_.count(prefix) > 0;
  return request_readers_.count(prefix) > 0 && reply_writers_.count(prefix) > 0 &&
         event_writers_.count(prefix) > 0;
}

bool ClientCore::prefix_is_dead_locked(const std::string& prefix) const {
  const auto it = participants_.find(prefix);
  return it != participants_.end() && !it->second.alive;
}

bool ClientCore::note_participant_locked(const std::string& prefix, const std::string& service,
                                         Actions& out) {
  if (service.empty() || prefix_is_dead_locked(prefix)) return false;
  auto& participant = participants_[prefix];
  participant.service = service;
  participant.alive = true;
  const auto& state = services_[service];
  if (state.incarnation.empty() || !state.alive) make_current_locked(service, prefix, out);
  return true;
}

void ClientCore::make_current_locked(const std::string& service, const std::string& prefix,
                                     Actions& out) {
  auto& state = services_[service];
  if (state.incarnation != prefix) {
    state.incarnation = prefix;
    // The info of another incarnation is not this one's.
    state.info.reset();
  }
  state.alive = true;
  changed_.notify_all();
  dispatch_locked(service, out);
}

void ClientCore::dispatch_locked(const std::string& service, Actions& out) {
  if (!ready_locked(service)) return;
  const std::string& incarnation = services_.find(service)->second.incarnation;
  for (auto& [seq, pending] : pending_) {
    if (pending.sent_to.empty() && pending.hand.service == service) {
      pending.sent_to = incarnation;
      to_write_.push_back(seq);
      out.wake_io = true;
    }
  }
  changed_.notify_all();
}

void ClientCore::lose_locked(const std::string& service, const std::string& why, Actions& out) {
  auto& state = services_[service];
  const std::string incarnation = state.incarnation;
  state.alive = false;
  if (auto it = participants_.find(incarnation); it != participants_.end()) {
    it->second.alive = false;
  }
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (!incarnation.empty() && it->second.sent_to == incarnation) {
      out.completions.emplace_back(
          std::move(it->second.done),
          make_reply(Code::service_lost,
                     why + " while " + command_name(it->second.request.command()) + " for " +
                         it->second.hand.to_string() + " was pending; it may or may not have run"));
      it = pending_.erase(it);
    } else {
      ++it;
    }
  }
  for (auto& [address, status] : statuses_) {
    if (address.service != service || !status.online) continue;
    status.online = false;
    status.service_lost = true;
    post_status_locked(status);
    HandEvent event;
    event.hand = address;
    event.name = status.name;
    event.kind = EventKind::offline;
    event.position = status.position;
    event.target = status.target_position;
    event.message = why;
    event.from_client = true;
    post_event_locked(event);
  }
  changed_.notify_all();
}

void ClientCore::on_participant_found(const std::string& prefix, const std::string& name) {
  if (!std::string_view(name).starts_with(kServiceParticipantPrefix)) return;
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    note_participant_locked(prefix, name.substr(kServiceParticipantPrefix.size()), out);
  }
  run(out);
}

void ClientCore::on_participant_left(const std::string& prefix) {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    request_readers_.erase(prefix);
    reply_writers_.erase(prefix);
    event_writers_.erase(prefix);
    const auto it = participants_.find(prefix);
    if (it == participants_.end() || !it->second.alive) return;
    it->second.alive = false;
    const std::string service = it->second.service;
    const auto state = services_.find(service);
    if (state == services_.end() || state->second.incarnation != prefix || !state->second.alive) {
      return;
    }
    lose_locked(service, "service '" + service + "' left the domain", out);
    // Another live participant of that name (a newer instance that was not
    // yet current) takes over; the latest started first.
    const Participant* best = nullptr;
    std::string best_prefix;
    for (const auto& [other, p] : participants_) {
      if (!p.alive || p.service != service) continue;
      if (best == nullptr || (p.has_info && (!best->has_info || p.started_ns > best->started_ns))) {
        best = &p;
        best_prefix = other;
      }
    }
    if (best != nullptr) make_current_locked(service, best_prefix, out);
  }
  run(out);
}

namespace {
void count_match(std::multiset<std::string>& set, const std::string& prefix, bool matched) {
  if (matched) {
    set.insert(prefix);
  } else if (const auto it = set.find(prefix); it != set.end()) {
    set.erase(it);
  }
}
}  // namespace

void ClientCore::on_match(std::multiset<std::string>& set, const std::string& prefix,
                          bool matched) {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    count_match(set, prefix, matched);
    if (const auto p = participants_.find(prefix); p != participants_.end() && p->second.alive) {
      dispatch_locked(p->second.service, out);
    }
  }
  run(out);
}

void ClientCore::on_request_reader_matched(const std::string& prefix, bool matched) {
  on_match(request_readers_, prefix, matched);
}

void ClientCore::on_reply_writer_matched(const std::string& prefix, bool matched) {
  on_match(reply_writers_, prefix, matched);
}

void ClientCore::on_event_writer_matched(const std::string& prefix, bool matched) {
  on_match(event_writers_, prefix, matched);
}

void ClientCore::on_info(const std::string& prefix, const msg::ServiceInfo& info) {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_ || !note_participant_locked(prefix, info.service(), out)) return;
    auto& participant = participants_[prefix];
    participant.has_info = true;
    participant.started_ns = info.started_ns();
    auto& state = services_[info.service()];
    if (state.incarnation != prefix) {
      const auto current = participants_.find(state.incarnation);
      const bool newer = current == participants_.end() || !current->second.has_info ||
                         info.started_ns() > current->second.started_ns;
      if (!newer) return;  // an older instance still around: the current one stays
      lose_locked(info.service(), "service '" + info.service() + "' restarted", out);
      make_current_locked(info.service(), prefix, out);
    }
    state.info = to_public(info);
    changed_.notify_all();
  }
  run(out);
}

void ClientCore::on_status(const std::string& prefix, const msg::HandStatus& sample) {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_ || !note_participant_locked(prefix, sample.service(), out)) return;
    HandStatus status = to_public(sample);
    post_status_locked(status);
    statuses_[status.address] = std::move(status);
    changed_.notify_all();
  }
  run(out);
}

void ClientCore::on_event(const std::string& prefix, const msg::HandEvent& sample) {
  std::lock_guard lock(mutex_);
  if (closed_ || prefix_is_dead_locked(prefix)) return;
  post_event_locked(to_public(sample));
}

void ClientCore::on_reply(const msg::CommandReply& reply) {
  // Every client reads every reply on the topic: only our own client_id and a
  // request we are waiting for resolve anything.
  if (reply.client_id() != client_id_) return;
  Done done;
  {
    std::lock_guard lock(mutex_);
    const auto it = pending_.find(reply.request_seq());
    if (it == pending_.end() || it->second.request.command() != reply.command()) return;
    done = std::move(it->second.done);
    pending_.erase(it);
  }
  done(to_reply(reply));
}

// ---------------------------------------------------------------------------
// What the client knows

ServiceInfo ClientCore::info_locked(const std::string& name, const ServiceState& s) const {
  ServiceInfo info = s.info.value_or(ServiceInfo{});
  info.name = name;
  info.ready = ready_locked(name);
  return info;
}

std::vector<ServiceInfo> ClientCore::services() const {
  std::lock_guard lock(mutex_);
  std::vector<ServiceInfo> out;
  for (const auto& [name, state] : services_) out.push_back(info_locked(name, state));
  return out;
}

std::optional<ServiceInfo> ClientCore::service(std::string_view name) const {
  std::lock_guard lock(mutex_);
  const auto it = services_.find(name);
  if (it == services_.end()) return std::nullopt;
  return info_locked(it->first, it->second);
}

std::vector<HandStatus> ClientCore::hands() const {
  std::lock_guard lock(mutex_);
  std::vector<HandStatus> out;
  for (const auto& [address, status] : statuses_) out.push_back(status);
  return out;
}

std::optional<HandStatus> ClientCore::status(const HandAddress& address) const {
  std::lock_guard lock(mutex_);
  const auto it = statuses_.find(address);
  if (it == statuses_.end()) return std::nullopt;
  return it->second;
}

std::vector<KnownHand> ClientCore::known_hands_locked() const {
  std::vector<KnownHand> known;
  for (const auto& [address, status] : statuses_) known.push_back(KnownHand{address, status.name});
  for (const auto& [name, state] : services_) {
    if (!state.info) continue;
    for (const auto& bus : state.info->buses) {
      for (const auto& hand : bus.hands) {
        HandAddress address{name, bus.name, hand.can_id};
        if (statuses_.count(address) == 0) known.push_back(KnownHand{address, hand.name});
      }
    }
  }
  return known;
}

std::vector<KnownHand> ClientCore::known_hands() const {
  std::lock_guard lock(mutex_);
  return known_hands_locked();
}

Found<ServiceInfo> ClientCore::wait_for_service(std::string_view name, Timeout timeout) {
  std::unique_lock lock(mutex_);
  std::optional<ServiceInfo> found;
  const auto check = [&] {
    if (closed_) return true;
    for (const auto& [service, state] : services_) {
      // Without the info reader no ServiceInfo ever comes: the name is all we know.
      if ((name.empty() || service == name) && (state.info || !has_info_reader_) &&
          ready_locked(service)) {
        found = info_locked(service, state);
        return true;
      }
    }
    return false;
  };
  changed_.wait_for(lock, effective(timeout), check);
  if (found) return *found;
  if (closed_) return {Code::not_connected, error_.empty() ? "the client was closed" : error_};
  const std::string which =
      name.empty() ? "no dh3 service" : "no service '" + std::string(name) + "'";
  return {Code::no_service, which + " found on DDS domain " + std::to_string(options_.domain) +
                                " within " + describe_duration(effective(timeout))};
}

bool ClientCore::wait_for_statuses(Timeout timeout) {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, effective(timeout), [&] {
    if (closed_) return false;
    for (const auto& [name, state] : services_) {
      if (!ready_locked(name)) continue;
      if (!state.info) {
        if (has_info_reader_) return false;
        // No info to list its hands: at least one of them must have reported.
        const bool any = std::any_of(statuses_.begin(), statuses_.end(),
                                     [&](const auto& s) { return s.first.service == name; });
        if (!any) return false;
        continue;
      }
      for (const auto& bus : state.info->buses) {
        for (const auto& hand : bus.hands) {
          if (statuses_.count(HandAddress{name, bus.name, hand.can_id}) == 0) return false;
        }
      }
    }
    return true;
  });
}

Found<HandAddress> ClientCore::wait_for_hand(const HandSpec& spec, Timeout timeout) {
  std::unique_lock lock(mutex_);
  std::optional<Found<HandAddress>> answer;
  const auto check = [&] {
    if (closed_) return true;
    auto resolved = resolve_hand(spec, known_hands_locked());
    if (!resolved) {
      // More hands can only make an ambiguous name more ambiguous.
      if (resolved.code() == Code::invalid_argument) {
        answer = std::move(resolved);
        return true;
      }
      return false;
    }
    if (statuses_.count(*resolved) == 0) return false;
    answer = std::move(resolved);
    return true;
  };
  changed_.wait_for(lock, effective(timeout), check);
  if (answer) return std::move(*answer);
  if (closed_) return {Code::not_connected, error_.empty() ? "the client was closed" : error_};
  const std::string within = " within " + describe_duration(effective(timeout));
  if (spec.service) {
    const auto it = services_.find(*spec.service);
    if (it == services_.end() || !it->second.alive) {
      return {Code::no_service, "no service '" + *spec.service + "' found on DDS domain " +
                                    std::to_string(options_.domain) + within};
    }
  } else if (std::none_of(services_.begin(), services_.end(),
                          [](const auto& s) { return s.second.alive; })) {
    return {Code::no_service,
            "no dh3 service found on DDS domain " + std::to_string(options_.domain) + within};
  }
  auto resolved = resolve_hand(spec, known_hands_locked());
  if (!resolved) return resolved;
  return {Code::unknown_hand, "service '" + resolved->service + "' has no hand " + resolved->bus +
                                  "/" + std::to_string(resolved->can_id) + " (no status for it" +
                                  within + ")"};
}

std::optional<HandStatus> ClientCore::wait_status(
    const HandAddress& address, const std::function<bool(const HandStatus&)>& pred,
    Timeout timeout) {
  std::unique_lock lock(mutex_);
  std::optional<HandStatus> found;
  changed_.wait_for(lock, effective(timeout), [&] {
    if (closed_) return true;
    const auto it = statuses_.find(address);
    if (it == statuses_.end() || !pred(it->second)) return false;
    found = it->second;
    return true;
  });
  return found;
}

// ---------------------------------------------------------------------------
// Subscriptions

void ClientCore::post_status_locked(const HandStatus& status) {
  std::vector<std::shared_ptr<SubscriptionState>> targets;
  for (const auto& sub : status_subs_) {
    if (!sub->only || *sub->only == status.address) targets.push_back(sub);
  }
  if (targets.empty()) return;
  dispatcher_.post([targets = std::move(targets), status] {
    for (const auto& sub : targets) {
      std::lock_guard run(sub->run_mutex);
      if (sub->active) run_guarded([&] { sub->on_status(status); });
    }
  });
}

void ClientCore::post_event_locked(const HandEvent& event) {
  std::vector<std::shared_ptr<SubscriptionState>> targets;
  for (const auto& sub : event_subs_) {
    if (!sub->only || *sub->only == event.hand) targets.push_back(sub);
  }
  if (targets.empty()) return;
  dispatcher_.post([targets = std::move(targets), event] {
    for (const auto& sub : targets) {
      std::lock_guard run(sub->run_mutex);
      if (sub->active) run_guarded([&] { sub->on_event(event); });
    }
  });
}

std::shared_ptr<SubscriptionState> ClientCore::subscribe_events(EventCallback callback,
                                                                std::optional<HandAddress> only) {
  auto state = std::make_shared<SubscriptionState>();
  state->on_event = std::move(callback);
  state->only = std::move(only);
  state->core = weak_from_this();
  std::lock_guard lock(mutex_);
  if (closed_) {
    state->active = false;
  } else {
    event_subs_.push_back(state);
  }
  return state;
}

std::shared_ptr<SubscriptionState> ClientCore::subscribe_status(StatusCallback callback,
                                                                std::optional<HandAddress> only) {
  auto state = std::make_shared<SubscriptionState>();
  state->on_status = std::move(callback);
  state->only = std::move(only);
  state->core = weak_from_this();
  std::lock_guard lock(mutex_);
  if (closed_) {
    state->active = false;
    return state;
  }
  // The statuses known now go first, posted under the same lock as later
  // samples, so the subscriber sees every hand's statuses in order.
  std::vector<HandStatus> known;
  for (const auto& [address, status] : statuses_) {
    if (!state->only || *state->only == address) known.push_back(status);
  }
  if (!known.empty()) {
    dispatcher_.post([state, known = std::move(known)] {
      std::lock_guard run(state->run_mutex);
      for (const auto& status : known) {
        if (!state->active) break;
        run_guarded([&] { state->on_status(status); });
      }
    });
  }
  status_subs_.push_back(state);
  return state;
}

void ClientCore::unsubscribe(const std::shared_ptr<SubscriptionState>& state) {
  state->active = false;
  {
    std::lock_guard lock(mutex_);
    std::erase(event_subs_, state);
    std::erase(status_subs_, state);
  }
  // Wait for a callback in progress on the dispatcher, unless we are it (an
  // unsubscribe from inside a callback).
  if (!dispatcher_.on_dispatcher_thread()) {
    std::lock_guard wait(state->run_mutex);
  }
}

}  // namespace dh3::detail
