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

namespace {

using Done = ClientCore::Done;

std::int32_t ttl_ms(std::chrono::milliseconds ttl) {
  // Out-of-range values are refused by the range check, not wrapped.
  const auto ms = ttl.count();
  if (ms > INT32_MAX) return INT32_MAX;
  if (ms < INT32_MIN) return INT32_MIN;
  return static_cast<std::int32_t>(ms);
}

/// A `done` that fulfils the future it comes with, on the thread that ends the call.
template <typename R>
std::pair<std::function<void(R)>, std::future<R>> promised() {
  auto promise = std::make_shared<std::promise<R>>();
  auto future = promise->get_future();
  return {[promise](R reply) { promise->set_value(std::move(reply)); }, std::move(future)};
}

/// The closing force, then the opening force if given (both checked before
/// anything is sent: a bad opening force must not leave the closing force changed).
void start_set_force(const std::shared_ptr<ClientCore>& core, const HandAddress& address,
                     std::int32_t closing, std::optional<std::int32_t> opening, Timeout timeout,
                     Done done) {
  if (opening) {
    if (auto checked = ClientCore::check(address, msg::SET_OPENING_FORCE, *opening); !checked) {
      done(std::move(checked).error());
      return;
    }
  }
  core->call(address, msg::SET_CLOSING_FORCE, closing, 0, timeout,
             [core, address, opening, timeout, done = std::move(done)](Reply reply) mutable {
               if (!reply.ok() || !opening) {
                 done(std::move(reply));
                 return;
               }
               core->call(address, msg::SET_OPENING_FORCE, *opening, 0, timeout, std::move(done));
             });
}

}  // namespace

// The commands, each once: its name, its parameters before the timeout and
// their names (each followed by a comma), and how it starts with `timeout`
// and `done` (ClientCore::Done). DH3_CALL_FORMS makes the three forms of each
// from it: with a callback (run on the client's callback thread), with a
// std::future, and blocking.
#define DH3_HAND_COMMANDS(X)                                                                    \
  X(initialize, (), (), core_->call(address_, msg::INITIALIZE, 0, 0, timeout, std::move(done))) \
  X(move_to, (std::int32_t position, ), (position, ),                                           \
    core_->call(address_, msg::MOVE, position, 0, timeout, std::move(done)))                    \
  X(rotate_to, (std::int32_t percent, ), (percent, ),                                           \
    core_->call(address_, msg::ROTATE, percent, 0, timeout, std::move(done)))                   \
  X(set_force, (std::int32_t closing, std::optional<std::int32_t> opening, ),                   \
    (closing, opening, ),                                                                       \
    start_set_force(core_, address_, closing, opening, timeout, std::move(done)))               \
  X(grasp, (std::int32_t force, ), (force, ),                                                   \
    core_->call(address_, msg::GRASP, force, 0, timeout, std::move(done)))                      \
  X(release, (std::int32_t position, ), (position, ),                                           \
    core_->call(address_, msg::RELEASE, position, 0, timeout, std::move(done)))                 \
  X(stop, (), (), core_->call(address_, msg::STOP, 0, 0, timeout, std::move(done)))             \
  X(read, (std::uint16_t register_code, ), (register_code, ),                                   \
    core_->call(address_, msg::READ_REGISTER, 0, register_code, timeout, std::move(done)))      \
  X(set_can_id, (std::int32_t can_id, ), (can_id, ),                                            \
    core_->call(address_, msg::SET_CAN_ID, can_id, 0, timeout, std::move(done)))                \
  X(set_baud_rate, (std::int32_t index, ), (index, ),                                           \
    core_->call(address_, msg::SET_BAUD_RATE, index, 0, timeout, std::move(done)))              \
  X(scan_bus, (), (),                                                                           \
    core_->call(HandAddress{address_.service, address_.bus, 0}, msg::SCAN, 0, 0, timeout,       \
                std::move(done)))                                                               \
  X(acquire_lease, (std::chrono::milliseconds ttl, ), (ttl, ),                                  \
    core_->call(address_, msg::ACQUIRE_LEASE, ttl_ms(ttl), 0, timeout, std::move(done)))        \
  X(renew_lease, (std::chrono::milliseconds ttl, ), (ttl, ),                                    \
    core_->call(address_, msg::RENEW_LEASE, ttl_ms(ttl), 0, timeout, std::move(done)))          \
  X(release_lease, (), (),                                                                      \
    core_->call(address_, msg::RELEASE_LEASE, 0, 0, timeout, std::move(done)))

#define DH3_CLIENT_COMMANDS(X)                                                      \
  X(scan, (const std::string& service, const std::string& bus, ), (service, bus, ), \
    core_->call(HandAddress{service, bus, 0}, msg::SCAN, 0, 0, timeout, std::move(done)))

#define DH3_UNPARENTHESIZED(...) __VA_ARGS__
#define DH3_CALL_FORMS(Class, name, params, args, start)                                         \
  void Class::name##_async(DH3_UNPARENTHESIZED params ReplyCallback callback, Timeout timeout) { \
    Done done = core_->on_callback_thread(std::move(callback));                                  \
    start;                                                                                       \
  }                                                                                              \
  std::future<Reply> Class::name##_async(DH3_UNPARENTHESIZED params Timeout timeout) {           \
    auto [done, future] = promised<Reply>();                                                     \
    start;                                                                                       \
    return std::move(future);                                                                    \
  }                                                                                              \
  Reply Class::name(DH3_UNPARENTHESIZED params Timeout timeout) {                                \
    return name##_async(DH3_UNPARENTHESIZED args timeout).get();                                 \
  }
#define DH3_HAND_CALL_FORMS(name, params, args, start) \
  DH3_CALL_FORMS(Hand, name, params, args, start)
#define DH3_CLIENT_CALL_FORMS(name, params, args, start) \
  DH3_CALL_FORMS(Client, name, params, args, start)

DH3_HAND_COMMANDS(DH3_HAND_CALL_FORMS)

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

DH3_CLIENT_COMMANDS(DH3_CLIENT_CALL_FORMS)

void Client::group_async(GroupCommand command, std::vector<HandAddress> hands, std::int32_t value,
                         GroupReplyCallback callback, Timeout timeout) {
  core_->group_call(command, hands, value, timeout, core_->on_callback_thread(std::move(callback)));
}
std::future<GroupReply> Client::group_async(GroupCommand command, std::vector<HandAddress> hands,
                                            std::int32_t value, Timeout timeout) {
  auto [done, future] = promised<GroupReply>();
  core_->group_call(command, hands, value, timeout, std::move(done));
  return std::move(future);
}
GroupReply Client::group(GroupCommand command, const std::vector<HandAddress>& hands,
                         std::int32_t value, Timeout timeout) {
  return group_async(command, hands, value, timeout).get();
}

Subscription Client::subscribe(EventCallback callback, std::optional<HandAddress> only) {
  return Subscription(core_->subscribe_events(std::move(callback), std::move(only)));
}

Subscription Client::subscribe_status(StatusCallback callback, std::optional<HandAddress> only) {
  return Subscription(core_->subscribe_status(std::move(callback), std::move(only)));
}

}  // namespace dh3
