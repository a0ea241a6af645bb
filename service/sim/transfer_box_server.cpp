#include "sim/transfer_box_server.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <optional>
#include <sstream>

#include "protocol/codec.hpp"

namespace dh3::sim {

namespace {

// Nothing waits longer than this, so a lost wake-up costs at most this much.
constexpr int kMaxPollMs = 1000;
constexpr std::size_t kReadChunk = 4096;
constexpr std::size_t kMaxControlLine = 4096;

std::string errno_text() {
  return std::strerror(errno);
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t at = 0;
  while (at < line.size()) {
    while (at < line.size() && (line[at] == ' ' || line[at] == '\t')) ++at;
    std::size_t end = at;
    while (end < line.size() && line[end] != ' ' && line[end] != '\t') ++end;
    if (end > at) words.push_back(line.substr(at, end - at));
    at = end;
  }
  return words;
}

template <typename T>
std::optional<T> parse_number(std::string_view text) {
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::optional<std::uint8_t> parse_hand_id(std::string_view text) {
  const auto id = parse_number<int>(text);
  if (!id || *id < 1 || *id > 255) return std::nullopt;
  return static_cast<std::uint8_t>(*id);
}

/// "none" (nullopt) or a percentage 0-100 into `place`; false if neither.
bool parse_place(std::string_view text, std::optional<std::int32_t>& place) {
  if (text == "none") {
    place.reset();
    return true;
  }
  const auto value = parse_number<std::int32_t>(text);
  if (!value || *value < 0 || *value > 100) return false;
  place = *value;
  return true;
}

void write_all(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t written = ::write(fd, text.data(), text.size());
    if (written < 0) {
      if (errno == EINTR) continue;
      spdlog::warn("dh3-sim: control answer not written: {}", errno_text());
      return;
    }
    text.remove_prefix(static_cast<std::size_t>(written));
  }
}

bool set_nonblocking(int fd) {
  const int flags = ::fcntl(fd, F_GETFL, 0);
  return flags >= 0 && ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) == 0;
}

}  // namespace

const std::string_view kControlHelp =
    "Control commands (one per line on stdin; each is answered on stdout by one line\n"
    "starting with \"ok\" or \"error\"):\n"
    "  drop ID            the object held by hand ID slips out (grip status leaves 3)\n"
    "  object ID POS|none place an object at position POS (0-100) or remove it\n"
    "  obstacle ID POS|none  place a rotation obstacle at POS or remove it\n"
    "  mute ID            hand ID stops answering (requests are lost)\n"
    "  unmute ID          hand ID answers again\n"
    "  delay ID MS        hand ID answers MS milliseconds after each request\n"
    "  corrupt ID N       the next N frames of hand ID have their low data byte flipped\n"
    "  reboot ID          power-cycle hand ID (a stored CAN ID takes effect)\n"
    "  state ID           print hand ID's true state\n"
    "  hands              list the hands' CAN IDs\n"
    "  kick               close every client connection (simulates link loss)\n"
    "  quit               stop dh3-sim\n";

std::string_view to_string(ServerError error) {
  switch (error) {
    case ServerError::bad_address:
      return "bad_address";
    case ServerError::socket_failed:
      return "socket_failed";
    case ServerError::bind_failed:
      return "bind_failed";
    case ServerError::listen_failed:
      return "listen_failed";
  }
  return "invalid ServerError";
}

TransferBoxServer::TransferBoxServer(TransferBoxServerOptions options, const Clock& clock)
    : options_(std::move(options)), clock_(clock) {}

Result<std::unique_ptr<TransferBoxServer>, ServerError> TransferBoxServer::open(
    TransferBoxServerOptions options, const Clock& clock) {
  std::unique_ptr<TransferBoxServer> server(new TransferBoxServer(std::move(options), clock));
  const TimePoint now = clock.now();
  for (const SimHandOptions& hand : server->options_.hands) {
    if (server->hands_.add(hand, now)) {
      spdlog::warn("dh3-sim: hand {} given twice, keeping the last", hand.id);
    }
  }
  if (auto listening = server->listen(); !listening) return fail(listening.error());
  if (server->options_.control_in >= 0) set_nonblocking(server->options_.control_in);
  return server;
}

Result<void, ServerError> TransferBoxServer::listen() {
  const std::string host = options_.host == "localhost" ? "127.0.0.1" : options_.host;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(options_.port);
  if (::inet_pton(AF_INET, host.c_str(), &address.sin_addr) != 1) {
    spdlog::error("dh3-sim: '{}' is not an IPv4 address", options_.host);
    return fail(ServerError::bad_address);
  }
  if (::pipe2(wake_pipe_, O_NONBLOCK | O_CLOEXEC) != 0) {
    spdlog::error("dh3-sim: pipe: {}", errno_text());
    return fail(ServerError::socket_failed);
  }
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) {
    spdlog::error("dh3-sim: socket: {}", errno_text());
    return fail(ServerError::socket_failed);
  }
  const int reuse = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &reuse, sizeof reuse);
  if (::bind(listen_fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    spdlog::error("dh3-sim: cannot listen on {}:{}: {}", host, options_.port, errno_text());
    return fail(ServerError::bind_failed);
  }
  if (::listen(listen_fd_, 16) != 0) {
    spdlog::error("dh3-sim: listen: {}", errno_text());
    return fail(ServerError::listen_failed);
  }
  socklen_t length = sizeof address;
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length);
  port_ = ntohs(address.sin_port);
  return {};
}

TransferBoxServer::~TransferBoxServer() {
  for (const std::unique_ptr<Client>& client : clients_) ::close(client->fd);
  if (listen_fd_ >= 0) ::close(listen_fd_);
  for (const int fd : wake_pipe_) {
    if (fd >= 0) ::close(fd);
  }
}

std::string TransferBoxServer::address() const {
  const std::string host = options_.host == "localhost" ? "127.0.0.1" : options_.host;
  return host + ":" + std::to_string(port_);
}

void TransferBoxServer::request_stop() {
  stop_requested_.store(true);
  const char byte = 's';
  [[maybe_unused]] const ssize_t ignored = ::write(wake_pipe_[1], &byte, 1);
}

void TransferBoxServer::run() {
  spdlog::info("dh3-sim: serving {} hand(s) on {}", hands_.size(), address());
  std::vector<pollfd> fds;
  while (!stop_requested_.load()) {
    serve_due(clock_.now());
    // Requests already decoded may have ended the run (a `quit` command).
    if (stop_requested_.load()) break;

    fds.clear();
    fds.push_back(pollfd{wake_pipe_[0], POLLIN, 0});
    fds.push_back(pollfd{listen_fd_, POLLIN, 0});
    const bool control_open = options_.control_in >= 0;
    if (control_open) fds.push_back(pollfd{options_.control_in, POLLIN, 0});
    const std::size_t first_client = fds.size();
    for (const std::unique_ptr<Client>& client : clients_) {
      const short events = client->out.empty() ? POLLIN : POLLIN | POLLOUT;
      fds.push_back(pollfd{client->fd, events, 0});
    }

    const int ready = ::poll(fds.data(), fds.size(), poll_timeout_ms(clock_.now()));
    if (ready < 0) {
      if (errno == EINTR) continue;
      spdlog::error("dh3-sim: poll: {}", errno_text());
      break;
    }
    if (ready == 0) continue;

    if (fds[0].revents != 0) {
      char drain[64];
      while (::read(wake_pipe_[0], drain, sizeof drain) > 0) {
      }
    }
    if (fds[1].revents & POLLIN) accept_clients();
    if (control_open && fds[2].revents != 0) read_control();
    // Clients accepted or kicked above are not in `fds`; match by descriptor.
    for (std::size_t i = first_client; i < fds.size(); ++i) {
      if (fds[i].revents == 0) continue;
      const auto found = std::find_if(clients_.begin(), clients_.end(),
                                      [&](const auto& client) { return client->fd == fds[i].fd; });
      if (found == clients_.end()) continue;
      Client& client = **found;
      if (fds[i].revents & (POLLIN | POLLHUP | POLLERR)) read_client(client);
      if (client.fd >= 0 && (fds[i].revents & POLLOUT)) write_client(client);
    }
    std::erase_if(clients_, [](const std::unique_ptr<Client>& client) { return client->fd < 0; });
  }
  kick_all();
  spdlog::info("dh3-sim: stopped");
}

void TransferBoxServer::serve_due(TimePoint now) {
  unsolicited_.clear();
  hands_.advance_all(now, unsolicited_);
  schedule(unsolicited_, 0);
  while (!scheduled_.empty() && scheduled_.top().due <= now) {
    const Scheduled frame = scheduled_.top();
    scheduled_.pop();
    for (const std::unique_ptr<Client>& client : clients_) {
      if (client->fd >= 0 && (frame.client_id == 0 || frame.client_id == client->id)) {
        queue_for(*client, frame.message);
      }
    }
  }
  for (const std::unique_ptr<Client>& client : clients_) {
    if (client->fd >= 0 && !client->out.empty()) write_client(*client);
  }
}

void TransferBoxServer::schedule(const std::vector<Outgoing>& frames, std::uint64_t client_id) {
  for (const Outgoing& frame : frames) {
    scheduled_.push(Scheduled{frame.due, next_sequence_++, client_id, frame.message});
  }
}

int TransferBoxServer::poll_timeout_ms(TimePoint now) const {
  std::optional<TimePoint> next = hands_.next_unsolicited_at();
  if (!scheduled_.empty() && (!next || scheduled_.top().due < *next)) next = scheduled_.top().due;
  if (!next) return kMaxPollMs;
  if (*next <= now) return 0;
  // Round up: waking early would only spin until the frame is due.
  const auto wait = std::chrono::ceil<std::chrono::milliseconds>(*next - now).count();
  return static_cast<int>(std::min<std::int64_t>(wait, kMaxPollMs));
}

void TransferBoxServer::accept_clients() {
  for (;;) {
    sockaddr_in peer{};
    socklen_t length = sizeof peer;
    const int fd = ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&peer), &length,
                             SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
        spdlog::warn("dh3-sim: accept: {}", errno_text());
      }
      return;
    }
    // Frames are tiny and latency matters more than packing them.
    const int no_delay = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &no_delay, sizeof no_delay);
    auto client = std::make_unique<Client>();
    client->fd = fd;
    client->id = next_client_id_++;
    char text[INET_ADDRSTRLEN] = {};
    ::inet_ntop(AF_INET, &peer.sin_addr, text, sizeof text);
    client->peer = std::string(text) + ":" + std::to_string(ntohs(peer.sin_port));
    spdlog::info("dh3-sim: client {} connected from {}", client->id, client->peer);
    clients_.push_back(std::move(client));
  }
}

void TransferBoxServer::read_client(Client& client) {
  std::uint8_t buffer[kReadChunk];
  for (;;) {
    const ssize_t got = ::recv(client.fd, buffer, sizeof buffer, 0);
    if (got == 0) {
      close_client(client, "closed by the client");
      return;
    }
    if (got < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) close_client(client, errno_text());
      return;
    }
    decoded_.clear();
    const std::uint64_t skipped_before = client.decoder.bytes_skipped();
    client.decoder.feed(std::span(buffer, static_cast<std::size_t>(got)), decoded_);
    if (client.decoder.bytes_skipped() != skipped_before) {
      spdlog::debug("dh3-sim: client {}: skipped {} byte(s) that are no frame", client.id,
                    client.decoder.bytes_skipped() - skipped_before);
    }
    for (const protocol::Message& request : decoded_) {
      const TimePoint now = clock_.now();
      replies_.clear();
      unsolicited_.clear();
      const std::size_t reached = hands_.deliver(request, now, replies_, unsolicited_);
      spdlog::debug("dh3-sim: client {}: {} ({} hand(s), {} repl(ies))", client.id,
                    protocol::describe(request), reached, replies_.size());
      schedule(replies_, client.id);
      schedule(unsolicited_, 0);
    }
    serve_due(clock_.now());
    if (client.fd < 0 || static_cast<std::size_t>(got) < sizeof buffer) return;
  }
}

void TransferBoxServer::queue_for(Client& client, const protocol::Message& message) {
  const protocol::BoxFrame frame = protocol::encode_box_frame(message);
  client.out.insert(client.out.end(), frame.begin(), frame.end());
  if (client.out.size() > options_.max_pending_bytes) {
    close_client(client, "it does not read its replies");
  }
}

void TransferBoxServer::write_client(Client& client) {
  while (!client.out.empty()) {
    const ssize_t sent =
        ::send(client.fd, client.out.data(), client.out.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (sent < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) close_client(client, errno_text());
      return;
    }
    client.out.erase(client.out.begin(), client.out.begin() + sent);
  }
}

void TransferBoxServer::close_client(Client& client, std::string_view why) {
  if (client.fd < 0) return;
  spdlog::info("dh3-sim: client {} ({}) disconnected: {}", client.id, client.peer, why);
  ::close(client.fd);
  client.fd = -1;
  client.out.clear();
}

void TransferBoxServer::kick_all() {
  for (const std::unique_ptr<Client>& client : clients_) close_client(*client, "kicked");
  clients_.clear();
}

void TransferBoxServer::read_control() {
  char buffer[1024];
  for (;;) {
    const ssize_t got = ::read(options_.control_in, buffer, sizeof buffer);
    if (got == 0) {
      spdlog::info("dh3-sim: control channel closed; serving on");
      options_.control_in = -1;
      break;
    }
    if (got < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) {
        spdlog::warn("dh3-sim: control channel: {}", errno_text());
        options_.control_in = -1;
      }
      break;
    }
    control_buffer_.append(buffer, static_cast<std::size_t>(got));
  }
  std::size_t newline = 0;
  while ((newline = control_buffer_.find('\n')) != std::string::npos) {
    std::string line = control_buffer_.substr(0, newline);
    control_buffer_.erase(0, newline + 1);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (split_words(line).empty()) continue;
    answer_control(execute(line));
    if (stop_requested_.load()) return;
  }
  if (control_buffer_.size() > kMaxControlLine) {
    control_buffer_.clear();
    answer_control("error line too long");
  }
}

void TransferBoxServer::answer_control(const std::string& line) {
  if (options_.control_out >= 0) write_all(options_.control_out, line + "\n");
}

SimHand* TransferBoxServer::hand_now(std::uint8_t id) {
  SimHand* hand = hands_.find(id);
  if (hand == nullptr) return nullptr;
  const TimePoint now = clock_.now();
  schedule(hand->advance(now), 0);
  return hand;
}

std::string TransferBoxServer::execute(std::string_view command) {
  const std::vector<std::string_view> words = split_words(command);
  if (words.empty()) return "error empty command";
  const std::string_view verb = words[0];
  const std::size_t first = command.find_first_not_of(" \t");
  const std::size_t last = command.find_last_not_of(" \t");
  const std::string echo(command.substr(first, last - first + 1));
  spdlog::info("dh3-sim: control: {}", echo);

  if (verb == "quit" && words.size() == 1) {
    request_stop();
    return "ok quit";
  }
  if (verb == "kick" && words.size() == 1) {
    const std::size_t count = clients_.size();
    for (const std::unique_ptr<Client>& client : clients_) close_client(*client, "kicked");
    return "ok kick " + std::to_string(count);
  }
  if (verb == "hands" && words.size() == 1) {
    std::string answer = "ok hands";
    for (const std::uint8_t id : hands_.ids()) answer += " " + std::to_string(id);
    return answer;
  }

  // Every other command names a hand.
  static constexpr std::string_view kOneArgument[] = {"drop", "mute", "unmute", "reboot", "state"};
  static constexpr std::string_view kTwoArguments[] = {"object", "obstacle", "delay", "corrupt"};
  const bool one =
      std::find(std::begin(kOneArgument), std::end(kOneArgument), verb) != std::end(kOneArgument);
  const bool two = std::find(std::begin(kTwoArguments), std::end(kTwoArguments), verb) !=
                   std::end(kTwoArguments);
  if (!one && !two) return "error unknown command '" + std::string(verb) + "' (see --help)";
  if (words.size() != (one ? 2U : 3U)) {
    return "error " + std::string(verb) + " takes " + (one ? "ID" : "ID and a value");
  }
  const std::optional<std::uint8_t> id = parse_hand_id(words[1]);
  if (!id) return "error '" + std::string(words[1]) + "' is no hand ID (1-255)";
  SimHand* hand = hand_now(*id);
  if (hand == nullptr) return "error no hand " + std::to_string(*id);

  if (verb == "drop") {
    hand->drop_object();
  } else if (verb == "mute" || verb == "unmute") {
    hand->set_muted(verb == "mute");
  } else if (verb == "reboot") {
    std::uint8_t new_id = *id;
    hands_.with_hand(
        *id, [&](SimHand& h) { h.reboot(clock_.now()); }, &new_id);
    return "ok " + echo + " (now ID " + std::to_string(new_id) + ")";
  } else if (verb == "state") {
    std::ostringstream state;
    state << "ok state " << int{hand->id()} << " stored_id=" << int{hand->stored_id()}
          << " initialized=" << hand->initialized() << " position=" << hand->position()
          << " grip_status=" << static_cast<int>(hand->grip_status())
          << " rotation=" << hand->rotation()
          << " rotation_status=" << static_cast<int>(hand->rotation_status())
          << " closing_force=" << hand->closing_force()
          << " opening_force=" << hand->opening_force() << " muted=" << hand->muted();
    return state.str();
  } else if (verb == "object" || verb == "obstacle") {
    std::optional<std::int32_t> place;
    if (!parse_place(words[2], place)) return "error position must be 0-100 or none";
    if (verb == "object") {
      hand->place_object(place);
    } else {
      hand->place_rotation_obstacle(place);
    }
  } else if (verb == "delay") {
    const auto ms = parse_number<int>(words[2]);
    if (!ms || *ms < 0) return "error delay takes milliseconds >= 0";
    hand->set_reply_delay(std::chrono::milliseconds(*ms));
  } else if (verb == "corrupt") {
    const auto count = parse_number<int>(words[2]);
    if (!count || *count < 0) return "error corrupt takes a count >= 0";
    hand->corrupt_next_replies(*count);
  }
  return "ok " + echo;
}

}  // namespace dh3::sim
