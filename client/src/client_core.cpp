// ClientCore: the life cycle, and what each call, sample and match means for
// the collaborators client_core.hpp names.

#include "client_core.hpp"

#include <algorithm>
#include <variant>

#include "client_endpoints.hpp"
#include "conversions.hpp"
#include "hand_lookup.hpp"

namespace dh3::detail {

// ---------------------------------------------------------------------------
// Life cycle

ClientCore::ClientCore(ClientOptions options) : ClientCore(std::move(options), EndpointCreator{}) {}

ClientCore::ClientCore(ClientOptions options, const EndpointCreator& endpoints)
    : options_(std::move(options)) {
  endpoints_ = std::make_unique<ClientEndpoints>(*this);
  if (auto set_up_done = set_up(endpoints); !set_up_done) {
    error_ = std::move(set_up_done).error();
    endpoints_.reset();
    closed_ = true;
    return;
  }
  io_thread_ = std::thread([this] { io_loop(); });
}

ClientCore::~ClientCore() {
  close();
}

Result<void, std::string> ClientCore::set_up(const EndpointCreator& creator) {
  if (!options_.follow.empty()) {
    auto parsed = contract::parse_follow(options_.follow);
    if (!parsed) return fail(std::move(parsed).error());
    follow_ = std::move(parsed).value();
  }
  if (auto created = endpoints_->create_participant(options_); !created) {
    return fail(std::move(created).error());
  }
  client_id_ = endpoints_->client_id();
  if (auto made = endpoints_->create_endpoints(creator, client_id_, follow_); !made) {
    return fail(std::move(made).error());
  }
  can_command_ = endpoints_->can_command();
  can_group_ = endpoints_->can_group();
  has_info_reader_ = endpoints_->has_info_reader();
  {
    std::lock_guard lock(mutex_);
    tracker_.set_endpoints(can_command_, endpoints_->has_owner_reader());
    tracker_.set_receive_looker(endpoints_->receive_looker());
  }
  can_administer_ = endpoints_->can_administer();
  if (!can_command_) denied_message_ = ClientEndpoints::denied_message(options_);
  if (!can_administer_) admin_denied_message_ = ClientEndpoints::admin_denied_message(options_);
  return {};
}

bool ClientCore::connected() const {
  std::lock_guard lock(mutex_);
  return !closed_;
}

std::string ClientCore::closed_message() const {
  return error_.empty() ? "the client was closed" : error_;
}

void ClientCore::close() {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_ && !io_thread_.joinable() && endpoints_ == nullptr) return;
    closed_ = true;
    out.completions = calls_.end_all(make_reply(Code::not_connected, "the client was closed"));
  }
  io_wake_.notify_all();
  changed_.notify_all();
  // The io thread is the only writer: once it is gone no write races the deletion below.
  if (io_thread_.joinable()) io_thread_.join();
  {
    // Callers writing their own requests finish before the writer goes.
    std::unique_lock lock(mutex_);
    writes_done_.wait(lock, [this] { return calls_.writes_in_flight() == 0; });
  }
  run(out);
  endpoints_.reset();  // waits for listener callbacks in progress
  subscriptions_.stop();
}

bool ClientCore::followed(std::string_view service, std::string_view bus) const {
  if (!follow_) return true;
  return service == follow_->service &&
         (bus.empty() || follow_->bus.empty() || bus == follow_->bus);
}

// ---------------------------------------------------------------------------
// Calls

Result<void, Reply> ClientCore::check(const HandAddress& hand, msg::CommandType command,
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
  if (auto checked = check_request(request); !checked) {
    done(std::move(checked).error());
    return;
  }
  PendingCalls::Call call;
  call.hand = hand;
  call.request = std::move(request);
  call.timeout = effective(timeout);
  call.done = std::move(done);
  submit(std::move(call));
}

void ClientCore::group_call(GroupCommand command, const std::vector<HandAddress>& hands,
                            std::int32_t value, Timeout timeout, GroupDone done) {
  auto call = GroupCalls::make_call(command, hands, value, timeout, effective(timeout), done);
  if (!call) return done(std::move(call).error());
  if (!connected()) {
    return done(GroupCalls::refused(Code::not_connected, "the client is not connected"));
  }
  if (!can_command_ || !can_group_) {
    return done(GroupCalls::refused(Code::denied, "not permitted to publish group requests"));
  }
  submit(std::move(call).value());
}

void ClientCore::submit(PendingCalls::Call call) {
  std::uint64_t seq = 0;
  bool write_now = false;
  bool kick = false;
  std::optional<PendingCalls::Write> to_send;
  {
    std::unique_lock lock(mutex_);
    if (closed_) {
      lock.unlock();
      call.done(make_reply(Code::not_connected, closed_message()));
      return;
    }
    if (!can_command_ || (call.administrative() && !can_administer_)) {
      lock.unlock();
      call.done(make_reply(Code::denied, can_command_ ? admin_denied_message_ : denied_message_));
      return;
    }
    seq = calls_.next_seq();
    if (call.group) {
      call.group->request.client_id(client_id_);
      call.group->request.request_seq(seq);
    } else {
      call.request.client_id(client_id_);
      call.request.request_seq(seq);
    }
    call.deadline = Clock::now() + call.timeout;
    const std::string& service = call.hand.service;
    const bool ready = call.group              ? tracker_.group_ready(service)
                       : call.administrative() ? tracker_.admin_ready(service)
                                               : tracker_.ready(service);
    if (ready) {
      call.sent_to = tracker_.incarnation(service);
      // Written here, without waking the io thread, unless that could let it
      // overtake a request written or queued before it.
      if (calls_.queue_empty() && calls_.writes_in_flight() == 0 && !t_on_dds_listener) {
        write_now = true;
        calls_.begin_write();
        to_send = PendingCalls::write_of(seq, call);
      } else {
        calls_.queue(seq);
        kick = true;
      }
    }
    // The io thread must see this deadline if it comes before its next wake.
    if (calls_.add(seq, std::move(call))) kick = true;
    if (kick) io_kick_ = true;
  }
  if (kick) io_wake_.notify_all();
  if (write_now) write_request(*to_send);
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

void ClientCore::write_request(const PendingCalls::Write& write) {
  const std::uint64_t seq = write.seq;
  const bool group = std::holds_alternative<msg::GroupRequest>(write.request);
  bool written = false;
  if (group) {
    msg::GroupRequest sample = std::get<msg::GroupRequest>(write.request);
    written = endpoints_->write(sample, write.to);
  } else {
    written = endpoints_->write(std::get<msg::CommandRequest>(write.request), write.to);
  }
  Done failed;
  {
    std::lock_guard lock(mutex_);
    calls_.end_write();
    if (written) {
      requests_written_.fetch_add(1, std::memory_order_relaxed);
    } else if (auto call = calls_.take(seq)) {
      failed = std::move(call->done);
    }
  }
  writes_done_.notify_all();
  if (failed) {
    failed(make_reply(Code::not_connected, group ? "could not publish the group request"
                                                 : "could not publish the request"));
  }
}

void ClientCore::write_requests(std::unique_lock<std::mutex>& lock) {
  while (!closed_) {
    auto next = calls_.next_to_write();
    if (!next) return;
    calls_.begin_write();
    lock.unlock();
    write_request(*next);
    lock.lock();
  }
}

void ClientCore::io_loop() {
  std::unique_lock lock(mutex_);
  while (!closed_) {
    // Requests first: a deadline must not end a call whose request was about to go out.
    write_requests(lock);
    if (closed_) break;
    Actions lapsed;
    for (const auto& outcome : tracker_.confirm_lapses(Clock::now())) apply_locked(outcome, lapsed);
    if (!lapsed.completions.empty()) {
      lock.unlock();
      run(lapsed);
      lock.lock();
      continue;
    }
    auto expiry = calls_.expire(Clock::now());
    if (!expiry.expired.empty()) {
      std::vector<PendingCalls::Completion> singles;
      std::vector<PendingCalls::Completion> groups;
      for (auto& call : expiry.expired) {
        Reply reply =
            PendingCalls::expired_reply(call, tracker_.alive(call.hand.service), options_.domain,
                                        tracker_.sightings(call.hand.service));
        (call.group ? groups : singles).emplace_back(std::move(call.done), std::move(reply));
      }
      lock.unlock();
      PendingCalls::tell_acknowledgment(singles,
                                        [this] { return endpoints_->requests_acknowledged(); });
      for (auto& [done, reply] : singles) done(std::move(reply));
      for (auto& [done, reply] : groups) done(std::move(reply));
      lock.lock();
      continue;  // state may have changed while unlocked
    }
    io_kick_ = false;
    const auto next = std::min(expiry.next, tracker_.next_lapse());
    calls_.set_next_wake(next);
    const auto wake = [this] { return closed_ || io_kick_ || !calls_.queue_empty(); };
    if (next == Clock::time_point::max()) {
      io_wake_.wait(lock, wake);
    } else {
      io_wake_.wait_until(lock, next, wake);
    }
  }
}

void ClientCore::run(Actions& actions) {
  for (auto& [done, reply] : actions.completions) done(std::move(reply));
  actions.completions.clear();
  if (actions.wake_io) io_wake_.notify_all();
}

// ---------------------------------------------------------------------------
// From the DDS listeners

void ClientCore::apply_locked(const ServiceTracker::Outcome& outcome, Actions& out) {
  const std::string& ending = outcome.lost_service ? outcome.lost : outcome.end_calls_of;
  for (auto& ended : calls_.end_sent_to(outcome.keep_calls ? "" : ending, outcome.why)) {
    out.completions.push_back(std::move(ended));
  }
  const auto made_ns = ClientMadeEvents::now_ns();
  if (outcome.lost_service) {
    for (const HandStatus& status : cache_.mark_lost(outcome.service)) {
      subscriptions_.post_status(status);
      subscriptions_.post_event(made_events_.offline(status, outcome.why, made_ns));
    }
  }
  if (!outcome.taken_over_by.empty()) {
    for (const HandStatus& status : cache_.of_service(outcome.service)) {
      subscriptions_.post_event(ClientMadeEvents::taken_over(status, outcome.taken_over_from,
                                                             outcome.taken_over_by, made_ns));
    }
  }
  for (const HandStatus& status : cache_.mark_regained(outcome.regained)) {
    post_status_locked(outcome.regained, status);
  }
  if (outcome.may_dispatch) dispatch_locked(outcome.service, out);
  changed_.notify_all();
}

void ClientCore::dispatch_locked(const std::string& service, Actions& out) {
  if (!tracker_.ready(service)) {
    io_kick_ = out.wake_io = true;  // it may wait for its owner (next_lapse)
    return;
  }
  if (calls_.assign(service, tracker_.incarnation(service), tracker_.group_ready(service),
                    tracker_.admin_ready(service))) {
    out.wake_io = true;
  }
  changed_.notify_all();
}

void ClientCore::on_participant_found(const std::string& prefix, const std::string& name) {
  const auto announced = contract::announced_service(name);
  if (!announced) return;
  const std::string& service = *announced;
  // A follower knows only the service it follows.
  if (!followed(service)) return;
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    ServiceTracker::Outcome outcome;
    tracker_.participant_found(prefix, service, outcome);
    apply_locked(outcome, out);
  }
  run(out);
}

void ClientCore::on_participant_left(const std::string& prefix) {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    apply_locked(tracker_.participant_left(prefix), out);
  }
  run(out);
}

void ClientCore::on_matched(ServiceTracker::Endpoint endpoint, const std::string& prefix,
                            bool matched) {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    if (const auto service = tracker_.matched(endpoint, prefix, matched)) {
      dispatch_locked(*service, out);
    }
    changed_.notify_all();  // a group call may wait for it (group_ready)
  }
  run(out);
}

void ClientCore::on_info(const std::string& prefix, const msg::ServiceInfo& info) {
  infos_taken_.fetch_add(1, std::memory_order_relaxed);
  if (!followed(info.service())) return;
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    ServiceTracker::Outcome outcome;
    if (!tracker_.take_info(prefix, to_public(info), outcome) &&
        !tracker_.believed(prefix, info.service())) {
      not_owner_samples_.fetch_add(1, std::memory_order_relaxed);
    }
    apply_locked(outcome, out);
  }
  run(out);
}

void ClientCore::on_owner(const std::string& prefix, const msg::ServiceOwner& claim) {
  if (!followed(claim.service())) return;
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    ServiceTracker::Outcome outcome;
    tracker_.take_claim(contract::to_claim(claim, prefix), outcome);
    apply_locked(outcome, out);
    io_kick_ = out.wake_io = true;  // it may have a lapse to confirm (next_lapse)
  }
  run(out);
}

void ClientCore::on_owner_liveliness(const std::string& prefix, int change) {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    if (tracker_.owner_liveliness_changed(prefix, change)) {
      apply_locked(tracker_.owner_alive(prefix, true), out);
    } else {
      tracker_.owner_lapsed(prefix, Clock::now());  // the io thread confirms it if it stands
      io_kick_ = out.wake_io = true;
    }
  }
  run(out);
}

void ClientCore::on_status(const std::string& prefix, const msg::HandStatus& sample) {
  statuses_taken_.fetch_add(1, std::memory_order_relaxed);
  if (!followed(sample.service(), sample.bus())) return;
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    ServiceTracker::Outcome outcome;
    const bool known = tracker_.note_status(prefix, sample.service(), outcome);
    apply_locked(outcome, out);
    if (known) {
      take_status_locked(prefix, sample);
    } else {
      not_owner_samples_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  run(out);
}

void ClientCore::take_status_locked(const std::string& incarnation, const msg::HandStatus& sample) {
  HandStatus status = to_public(sample);
  if (!cache_.take(incarnation, status)) return;
  post_status_locked(incarnation, status);
  changed_.notify_all();
}

void ClientCore::post_status_locked(const std::string& incarnation, const HandStatus& status) {
  // Posted under mutex_: the subscribers see each hand's statuses in cache order.
  subscriptions_.post_status(status);
  if (auto online = made_events_.online(incarnation, status, ClientMadeEvents::now_ns())) {
    subscriptions_.post_event(*online);
  }
}

void ClientCore::on_event(const std::string& prefix, const msg::HandEvent& sample) {
  events_taken_.fetch_add(1, std::memory_order_relaxed);
  if (!followed(sample.hand().service(), sample.hand().bus())) return;
  std::lock_guard lock(mutex_);
  if (closed_) return;
  if (!tracker_.believed(prefix, sample.hand().service())) {
    not_owner_samples_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  HandEvent event = to_public(sample);
  if (made_events_.passes(prefix, event)) subscriptions_.post_event(event);
}

void ClientCore::on_reply(const std::string& prefix, const msg::CommandReply& reply) {
  // The reply reader's filter keeps our client_id; checked again in case
  // Fast DDS refused the filtered topic and we read the plain one.
  if (reply.client_id() != client_id_) {
    foreign_replies_taken_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  own_replies_.fetch_add(1, std::memory_order_relaxed);
  Done done;
  {
    std::lock_guard lock(mutex_);
    const PendingCalls::Call* call = calls_.find(reply.request_seq());
    if (call == nullptr || call->group || call->request.command() != reply.command()) return;
    // Another service of the name answered too (a duplicate before it saw the
    // owner): only the one the call went to is believed.
    if (!call->sent_to.empty() && call->sent_to != prefix) {
      not_owner_samples_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    // The hand's status as the command left it, cached (and posted) before the
    // call ends; the same sample on the status topic is then not news.
    if (reply.status().update_seq() != 0 && !closed_ && !call->sent_to.empty() &&
        !reply.status().service().empty() &&
        followed(reply.status().service(), reply.status().bus())) {
      take_status_locked(call->sent_to, reply.status());
    }
    done = std::move(calls_.take(reply.request_seq())->done);
  }
  done(to_reply(reply));
}

void ClientCore::on_group_reply(const msg::GroupReply& reply) {
  // Group replies travel unfiltered: other clients' count as foreign.
  if (reply.client_id() != client_id_) {
    foreign_replies_taken_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  GroupDone done;
  {
    std::lock_guard lock(mutex_);
    const PendingCalls::Call* call = calls_.find(reply.request_seq());
    if (call == nullptr || !call->group) return;
    done = std::move(calls_.take(reply.request_seq())->group->done);
  }
  own_replies_.fetch_add(1, std::memory_order_relaxed);
  done(GroupCalls::reply_of(reply));
}

// ---------------------------------------------------------------------------
// What the client knows, and the waits on it

std::vector<ServiceInfo> ClientCore::services() const {
  std::lock_guard lock(mutex_);
  return tracker_.services();
}

std::optional<ServiceInfo> ClientCore::service(std::string_view name) const {
  std::lock_guard lock(mutex_);
  return tracker_.service(name);
}

std::vector<HandStatus> ClientCore::hands() const {
  std::lock_guard lock(mutex_);
  return cache_.all();
}

std::optional<HandStatus> ClientCore::status(const HandAddress& address) const {
  std::lock_guard lock(mutex_);
  return cache_.find(address);
}

std::vector<KnownHand> ClientCore::known_hands() const {
  std::lock_guard lock(mutex_);
  return cache_.known_hands(tracker_.infos());
}

CommandTraffic ClientCore::command_traffic() const {
  CommandTraffic traffic;
  traffic.requests_written = requests_written_.load(std::memory_order_relaxed);
  traffic.own_replies = own_replies_.load(std::memory_order_relaxed);
  traffic.foreign_replies = foreign_replies_taken_.load(std::memory_order_relaxed);
  if (endpoints_ != nullptr) traffic.foreign_replies += endpoints_->replies_filtered();
  return traffic;
}

WatchTraffic ClientCore::watch_traffic() const {
  WatchTraffic traffic;
  traffic.statuses = statuses_taken_.load(std::memory_order_relaxed);
  traffic.events = events_taken_.load(std::memory_order_relaxed);
  traffic.infos = infos_taken_.load(std::memory_order_relaxed);
  traffic.not_owner = not_owner_samples_.load(std::memory_order_relaxed);
  if (endpoints_ != nullptr) traffic.dropped_on_arrival = endpoints_->follow_filtered();
  return traffic;
}

Found<ServiceInfo> ClientCore::wait_for_service(std::string_view name, Timeout timeout) {
  std::unique_lock lock(mutex_);
  std::optional<ServiceInfo> found;
  // Without the info reader no ServiceInfo ever comes: the name is all we know.
  changed_.wait_for(lock, effective(timeout), [&] {
    if (closed_) return true;
    found = tracker_.find_ready(name, has_info_reader_);
    return found.has_value();
  });
  if (found) return *found;
  if (closed_) return {Code::not_connected, closed_message()};
  return {Code::no_service, detail::no_service_found(name, options_.domain, effective(timeout),
                                                     tracker_.sightings(std::string(name)))};
}

bool ClientCore::wait_for_statuses(Timeout timeout) {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, effective(timeout), [&] {
    if (closed_) return false;
    for (const auto& [name, info] : tracker_.ready_services()) {
      if (!info) {
        if (has_info_reader_) return false;
        // No info to list its hands: at least one of them must have reported.
        if (!cache_.has_service(name)) return false;
        continue;
      }
      for (const auto& bus : info->buses) {
        if (!followed(name, bus.name)) continue;  // a follower of one bus has no other's
        for (const auto& hand : bus.hands) {
          if (!cache_.has(HandAddress{name, bus.name, hand.can_id})) return false;
        }
      }
    }
    return true;
  });
}

Found<HandAddress> ClientCore::wait_for_hand(const HandSpec& spec, Timeout timeout) {
  std::unique_lock lock(mutex_);
  std::optional<Found<HandAddress>> answer;
  // Refused once the live services' own lists rule the hand out, not at the wait's end.
  const auto ruled_out = [&] {
    std::vector<ServiceInfo> live;
    for (auto& info : tracker_.infos()) {
      if (tracker_.alive(info.name)) live.push_back(std::move(info));
    }
    auto why = detail::hand_ruled_out(spec, live);
    if (why) answer = Found<HandAddress>{Code::unknown_hand, std::move(*why)};
    return why.has_value();
  };
  const auto check = [&] {
    if (closed_) return true;
    auto resolved = resolve_hand(spec, cache_.known_hands(tracker_.infos()));
    if (!resolved) {
      // More hands can only make an ambiguous name more ambiguous.
      if (resolved.code() == Code::invalid_argument) {
        answer = std::move(resolved);
        return true;
      }
      return ruled_out();
    }
    if (!cache_.has(*resolved)) return ruled_out();
    answer = std::move(resolved);
    return true;
  };
  changed_.wait_for(lock, effective(timeout), check);
  if (answer) return std::move(*answer);
  if (closed_) return {Code::not_connected, closed_message()};
  if (spec.service ? !tracker_.alive(*spec.service) : !tracker_.any_alive()) {
    return {Code::no_service,
            detail::no_service_found(spec.service.value_or(""), options_.domain, effective(timeout),
                                     tracker_.sightings_if_named(spec.service))};
  }
  auto resolved = resolve_hand(spec, cache_.known_hands(tracker_.infos()));
  if (!resolved) return resolved;
  return {Code::unknown_hand, detail::no_status_for(*resolved, effective(timeout))};
}

std::optional<HandStatus> ClientCore::wait_status(
    const HandAddress& address, const std::function<bool(const HandStatus&)>& pred,
    Timeout timeout) {
  std::unique_lock lock(mutex_);
  std::optional<HandStatus> found;
  changed_.wait_for(lock, effective(timeout), [&] {
    if (closed_) return true;
    auto status = cache_.find(address);
    if (!status || !pred(*status)) return false;
    found = std::move(status);
    return true;
  });
  return found;
}

// ---------------------------------------------------------------------------
// Subscriptions

std::shared_ptr<SubscriptionState> ClientCore::new_subscription(std::optional<HandAddress> only) {
  auto state = std::make_shared<SubscriptionState>();
  state->only = std::move(only);
  state->core = weak_from_this();
  return state;
}

std::shared_ptr<SubscriptionState> ClientCore::add_subscription(
    std::shared_ptr<SubscriptionState> state, const std::function<void()>& add) {
  std::lock_guard lock(mutex_);
  if (closed_) {
    state->active = false;
  } else {
    add();
  }
  return state;
}

std::shared_ptr<SubscriptionState> ClientCore::subscribe_events(EventCallback callback,
                                                                std::optional<HandAddress> only) {
  auto state = new_subscription(std::move(only));
  state->on_event = std::move(callback);
  return add_subscription(state, [&] { subscriptions_.add_events(state); });
}

std::shared_ptr<SubscriptionState> ClientCore::subscribe_status(StatusCallback callback,
                                                                std::optional<HandAddress> only) {
  auto state = new_subscription(std::move(only));
  state->on_status = std::move(callback);
  // Under mutex_, which every later status is posted under: the subscriber
  // sees the statuses known now, then each later one, in order.
  return add_subscription(
      state, [&] { subscriptions_.add_status(state, cache_.matching(state->only)); });
}

void ClientCore::unsubscribe(const std::shared_ptr<SubscriptionState>& state) {
  subscriptions_.remove(state);
}

}  // namespace dh3::detail
