// dh3::Client, dh3::Hand and dh3::Subscription: thin handles on ClientCore.

#include "dh3/client.hpp"

#include "client_core.hpp"

namespace dh3 {

using detail::ClientCore;

// ---------------------------------------------------------------------------
// Subscription

Subscription::Subscription(std::shared_ptr<detail::SubscriptionState> state)
    : state_(std::move(state)) {}

Subscription::~Subscription() {
  unsubscribe();
}

Subscription::Subscription(Subscription&& other) noexcept : state_(std::move(other.state_)) {}

Subscription& Subscription::operator=(Subscription&& other) noexcept {
  if (this != &other) {
    unsubscribe();
    state_ = std::move(other.state_);
  }
  return *this;
}

void Subscription::unsubscribe() {
  if (!state_) return;
  auto state = std::move(state_);
  state_.reset();
  if (auto core = state->core.lock()) {
    core->unsubscribe(state);
  } else {
    state->active = false;  // the client is gone and its callbacks with it
  }
}

bool Subscription::active() const {
  return state_ && state_->active;
}

// ---------------------------------------------------------------------------
// Hand

Hand::Hand(std::shared_ptr<ClientCore> core, HandAddress address)
    : core_(std::move(core)), address_(std::move(address)) {}

std::optional<HandStatus> Hand::status() const {
  return core_->status(address_);
}

bool Hand::online() const {
  const auto s = status();
  return s && s->online;
}

std::optional<HandStatus> Hand::wait_until(const std::function<bool(const HandStatus&)>& pred,
                                           Timeout timeout) const {
  return core_->wait_status(address_, pred, timeout);
}

std::future<Reply> Hand::initialize_async(Timeout timeout) {
  return core_->call(address_, msg::INITIALIZE, 0, 0, timeout);
}
Reply Hand::initialize(Timeout timeout) {
  return initialize_async(timeout).get();
}

std::future<Reply> Hand::move_to_async(std::int32_t position, Timeout timeout) {
  return core_->call(address_, msg::MOVE, position, 0, timeout);
}
Reply Hand::move_to(std::int32_t position, Timeout timeout) {
  return move_to_async(position, timeout).get();
}

std::future<Reply> Hand::rotate_to_async(std::int32_t percent, Timeout timeout) {
  return core_->call(address_, msg::ROTATE, percent, 0, timeout);
}
Reply Hand::rotate_to(std::int32_t percent, Timeout timeout) {
  return rotate_to_async(percent, timeout).get();
}

std::future<Reply> Hand::set_force_async(std::int32_t closing, std::optional<std::int32_t> opening,
                                         Timeout timeout) {
  auto promise = std::make_shared<std::promise<Reply>>();
  auto future = promise->get_future();
  // Both values are checked before anything is sent: a bad opening force
  // must not leave the closing force changed.
  if (opening) {
    if (auto checked = ClientCore::check(address_, msg::SET_OPENING_FORCE, *opening); !checked) {
      promise->set_value(std::move(checked).error());
      return future;
    }
  }
  auto core = core_;
  const HandAddress address = address_;
  core_->call(address_, msg::SET_CLOSING_FORCE, closing, 0, timeout,
              [core, address, opening, timeout, promise](Reply reply) {
                if (!reply.ok() || !opening) {
                  promise->set_value(std::move(reply));
                  return;
                }
                core->call(address, msg::SET_OPENING_FORCE, *opening, 0, timeout,
                           [promise](Reply second) { promise->set_value(std::move(second)); });
              });
  return future;
}
Reply Hand::set_force(std::int32_t closing, std::optional<std::int32_t> opening, Timeout timeout) {
  return set_force_async(closing, opening, timeout).get();
}

std::future<Reply> Hand::grasp_async(std::int32_t force, Timeout timeout) {
  return core_->call(address_, msg::GRASP, force, 0, timeout);
}
Reply Hand::grasp(std::int32_t force, Timeout timeout) {
  return grasp_async(force, timeout).get();
}

std::future<Reply> Hand::release_async(std::int32_t position, Timeout timeout) {
  return core_->call(address_, msg::RELEASE, position, 0, timeout);
}
Reply Hand::release(std::int32_t position, Timeout timeout) {
  return release_async(position, timeout).get();
}

std::future<Reply> Hand::stop_async(Timeout timeout) {
  return core_->call(address_, msg::STOP, 0, 0, timeout);
}
Reply Hand::stop(Timeout timeout) {
  return stop_async(timeout).get();
}

std::future<Reply> Hand::read_async(std::uint16_t register_code, Timeout timeout) {
  return core_->call(address_, msg::READ_REGISTER, 0, register_code, timeout);
}
Reply Hand::read(std::uint16_t register_code, Timeout timeout) {
  return read_async(register_code, timeout).get();
}

std::future<Reply> Hand::set_can_id_async(std::int32_t can_id, Timeout timeout) {
  return core_->call(address_, msg::SET_CAN_ID, can_id, 0, timeout);
}
Reply Hand::set_can_id(std::int32_t can_id, Timeout timeout) {
  return set_can_id_async(can_id, timeout).get();
}

std::future<Reply> Hand::set_baud_rate_async(std::int32_t index, Timeout timeout) {
  return core_->call(address_, msg::SET_BAUD_RATE, index, 0, timeout);
}
Reply Hand::set_baud_rate(std::int32_t index, Timeout timeout) {
  return set_baud_rate_async(index, timeout).get();
}

std::future<Reply> Hand::scan_bus_async(Timeout timeout) {
  return core_->call(HandAddress{address_.service, address_.bus, 0}, msg::SCAN, 0, 0, timeout);
}
Reply Hand::scan_bus(Timeout timeout) {
  return scan_bus_async(timeout).get();
}

namespace {
std::int32_t ttl_ms(std::chrono::milliseconds ttl) {
  // Out-of-range values are refused by the range check, not wrapped.
  const auto ms = ttl.count();
  if (ms > INT32_MAX) return INT32_MAX;
  if (ms < INT32_MIN) return INT32_MIN;
  return static_cast<std::int32_t>(ms);
}
}  // namespace

std::future<Reply> Hand::acquire_lease_async(std::chrono::milliseconds ttl, Timeout timeout) {
  return core_->call(address_, msg::ACQUIRE_LEASE, ttl_ms(ttl), 0, timeout);
}
Reply Hand::acquire_lease(std::chrono::milliseconds ttl, Timeout timeout) {
  return acquire_lease_async(ttl, timeout).get();
}
std::future<Reply> Hand::renew_lease_async(std::chrono::milliseconds ttl, Timeout timeout) {
  return core_->call(address_, msg::RENEW_LEASE, ttl_ms(ttl), 0, timeout);
}
Reply Hand::renew_lease(std::chrono::milliseconds ttl, Timeout timeout) {
  return renew_lease_async(ttl, timeout).get();
}
std::future<Reply> Hand::release_lease_async(Timeout timeout) {
  return core_->call(address_, msg::RELEASE_LEASE, 0, 0, timeout);
}
Reply Hand::release_lease(Timeout timeout) {
  return release_lease_async(timeout).get();
}

Subscription Hand::subscribe(EventCallback callback) {
  return Subscription(core_->subscribe_events(std::move(callback), address_));
}

// ---------------------------------------------------------------------------
// Client

Client::Client(ClientOptions options) : core_(std::make_shared<ClientCore>(std::move(options))) {}

Client::~Client() {
  core_->close();
}

bool Client::connected() const {
  return core_->connected();
}
std::string Client::error() const {
  return core_->error();
}
bool Client::read_only() const {
  return core_->read_only();
}
std::string Client::client_id() const {
  return core_->client_id();
}
CommandTraffic Client::command_traffic() const {
  return core_->command_traffic();
}
WatchTraffic Client::watch_traffic() const {
  return core_->watch_traffic();
}

int Client::domain() const {
  return core_->options().domain;
}
std::chrono::milliseconds Client::default_timeout() const {
  return core_->options().default_timeout;
}

std::vector<ServiceInfo> Client::services() const {
  return core_->services();
}
std::optional<ServiceInfo> Client::service(std::string_view name) const {
  return core_->service(name);
}
std::vector<HandStatus> Client::hands() const {
  return core_->hands();
}
std::optional<HandStatus> Client::status(const HandAddress& address) const {
  return core_->status(address);
}

Found<ServiceInfo> Client::wait_for_service(std::string_view name, Timeout timeout) {
  return core_->wait_for_service(name, timeout);
}

bool Client::wait_for_statuses(Timeout timeout) {
  return core_->wait_for_statuses(timeout);
}

Hand Client::hand(const HandAddress& address) {
  return Hand(core_, address);
}

Found<Hand> Client::find_hand(std::string_view spec) {
  auto parsed = parse_hand_spec(spec);
  if (!parsed) return {parsed.code(), parsed.message()};
  auto resolved = resolve_hand(*parsed, core_->known_hands());
  if (!resolved) return {resolved.code(), resolved.message()};
  return Hand(core_, *resolved);
}

Found<Hand> Client::wait_for_hand(std::string_view spec, Timeout timeout) {
  auto parsed = parse_hand_spec(spec);
  if (!parsed) return {parsed.code(), parsed.message()};
  auto resolved = core_->wait_for_hand(*parsed, timeout);
  if (!resolved) return {resolved.code(), resolved.message()};
  return Hand(core_, *resolved);
}

std::future<Reply> Client::scan_async(const std::string& service, const std::string& bus,
                                      Timeout timeout) {
  return core_->call(HandAddress{service, bus, 0}, msg::SCAN, 0, 0, timeout);
}
Reply Client::scan(const std::string& service, const std::string& bus, Timeout timeout) {
  return scan_async(service, bus, timeout).get();
}

std::future<GroupReply> Client::group_async(GroupCommand command, std::vector<HandAddress> hands,
                                           std::int32_t value, Timeout timeout) {
  // The call blocks while it waits; a thread of its own keeps the caller free.
  return std::async(std::launch::async, [core = core_, command, hands = std::move(hands), value,
                                         timeout] {
    return core->group_call(command, hands, value, timeout);
  });
}
GroupReply Client::group(GroupCommand command, const std::vector<HandAddress>& hands,
                         std::int32_t value, Timeout timeout) {
  return core_->group_call(command, hands, value, timeout);
}

Subscription Client::subscribe(EventCallback callback, std::optional<HandAddress> only) {
  return Subscription(core_->subscribe_events(std::move(callback), std::move(only)));
}

Subscription Client::subscribe_status(StatusCallback callback, std::optional<HandAddress> only) {
  return Subscription(core_->subscribe_status(std::move(callback), std::move(only)));
}

}  // namespace dh3
