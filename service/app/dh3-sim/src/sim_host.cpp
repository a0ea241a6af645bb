#include "dh3/sim_server/sim_host.hpp"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <sstream>

#include "dh3/base/hand_ids.hpp"

namespace dh3::sim {

namespace {

// Nothing waits longer than this, so a lost wake-up costs at most this much.
constexpr int kMaxPollMs = 1000;
constexpr std::size_t kMaxControlLine = 4096;

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

/// "none" (nullopt) or a percentage 0-100.
Result<std::optional<std::int32_t>, std::string> parse_place(std::string_view text) {
  if (text == "none") return std::optional<std::int32_t>{};
  const auto value = parse_number<std::int32_t>(text);
  if (!value || *value < 0 || *value > 100) return fail("position must be 0-100 or none");
  return std::optional<std::int32_t>{*value};
}

void write_all(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t written = ::write(fd, text.data(), text.size());
    if (written < 0) {
      if (errno == EINTR) continue;
      spdlog::warn("dh3-sim: control answer not written: {}", errno_text(errno));
      return;
    }
    text.remove_prefix(static_cast<std::size_t>(written));
  }
}

std::string describe_state(const SimHand& hand) {
  std::ostringstream state;
  state << "ok state " << int{hand.id()} << " stored_id=" << int{hand.stored_id()}
        << " initialized=" << hand.initialized() << " position=" << hand.position()
        << " grip_status=" << static_cast<int>(hand.grip_status())
        << " rotation=" << hand.rotation()
        << " rotation_status=" << static_cast<int>(hand.rotation_status())
        << " closing_force=" << hand.closing_force() << " opening_force=" << hand.opening_force()
        << " muted=" << hand.muted() << " grip_status_since_ns="
        << std::chrono::duration_cast<std::chrono::nanoseconds>(
               hand.grip_status_since().time_since_epoch())
               .count();
  return state.str();
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
    "  state ID           print hand ID's true state (grip_status_since_ns: when the\n"
    "                     grip status took its value, steady clock, ns)\n"
    "  hands              list the hands' CAN IDs\n"
    "  violations         'ok N': interval violations so far (needs --min-interval-ms)\n"
    "  kick               close every client connection (TCP only; simulates link loss)\n"
    "  quit               stop dh3-sim\n";

SimHost::SimHost(SimHostOptions options, const Clock& clock)
    : options_(std::move(options)), clock_(clock), watch_(options_.min_interval) {
  const TimePoint now = clock_.now();
  if (options_.replay) {
    replay_.emplace(*options_.replay, now);
    return;
  }
  for (const SimHandOptions& hand : options_.hands) {
    if (hands_.add(hand, now))
      spdlog::warn("dh3-sim: hand {} given twice, keeping the last", hand.id);
  }
}

std::vector<std::uint8_t> SimHost::ids() const {
  return replay_ ? replay_->ids() : hands_.ids();
}

bool SimHost::answers_on(std::uint8_t id) const {
  const std::vector<std::uint8_t> all = ids();
  return std::find(all.begin(), all.end(), id) != all.end();
}

Result<void, std::string> SimHost::start() {
  int ends[2];
  if (::pipe2(ends, O_NONBLOCK | O_CLOEXEC) != 0) return fail(errno_text(errno));
  wake_read_.reset(ends[0]);
  wake_write_.reset(ends[1]);
  if (options_.control_in >= 0) set_nonblocking(options_.control_in);
  return {};
}

void SimHost::request_stop() {
  stop_requested_.store(true);
  const char byte = 's';
  [[maybe_unused]] const ssize_t ignored = ::write(wake_write_.get(), &byte, 1);
}

void SimHost::run(SimTransport& transport) {
  std::vector<pollfd> fds;
  while (!stop_requested_.load()) {
    serve_due(transport);
    // Requests already decoded may have ended the run (a `quit` command).
    if (stop_requested_.load()) break;

    fds.clear();
    fds.push_back(pollfd{wake_read_.get(), POLLIN, 0});
    const bool control_open = options_.control_in >= 0;
    if (control_open) fds.push_back(pollfd{options_.control_in, POLLIN, 0});
    const std::size_t first_transport = fds.size();
    transport.add_poll_fds(fds);

    const std::optional<TimePoint> timer = transport.next_timer();
    const int ready = ::poll(fds.data(), fds.size(), poll_timeout_ms(clock_.now(), timer));
    if (ready < 0) {
      if (errno == EINTR) continue;
      spdlog::error("dh3-sim: poll: {}", errno_text(errno));
      break;
    }
    if (ready > 0) {
      if (fds[0].revents != 0) {
        char drain[64];
        while (::read(wake_read_.get(), drain, sizeof drain) > 0) {
        }
      }
      if (control_open && fds[1].revents != 0) read_control(transport);
      if (stop_requested_.load()) break;
      transport.on_poll(std::span<const pollfd>(fds).subspan(first_transport));
    }
    if (timer && *timer <= clock_.now()) transport.on_timer(clock_.now());
  }
  transport.on_stop();
  spdlog::info("dh3-sim: stopped");
}

std::size_t SimHost::receive(const protocol::Message& request, std::uint64_t from,
                             std::optional<Duration> received) {
  const TimePoint now = clock_.now();
  if (watch_.enabled()) {
    const Duration at = received.value_or(now.time_since_epoch());
    if (request.hand_id != 0) {
      if (answers_on(request.hand_id)) watch_.note(request.hand_id, at, request);
    } else {
      for (const std::uint8_t id : ids()) watch_.note(id, at, request);
    }
  }
  replies_.clear();
  unsolicited_.clear();
  const std::size_t reached = replay_ ? replay_->deliver(request, now, replies_, unsolicited_)
                                      : hands_.deliver(request, now, replies_, unsolicited_);
  spdlog::debug("dh3-sim: peer {}: {} ({} hand(s), {} repl(ies))", from,
                protocol::describe(request), reached, replies_.size());
  schedule(replies_, from);
  schedule(unsolicited_, kEveryPeer);
  return reached;
}

void SimHost::serve_due(SimTransport& transport) {
  const TimePoint now = clock_.now();
  unsolicited_.clear();
  if (replay_) {
    replay_->advance_all(now, unsolicited_);
  } else {
    hands_.advance_all(now, unsolicited_);
  }
  schedule(unsolicited_, kEveryPeer);
  while (!scheduled_.empty() && scheduled_.top().due <= now) {
    const Scheduled frame = scheduled_.top();
    scheduled_.pop();
    transport.send(frame.destination, frame.message);
  }
  transport.flush();
}

void SimHost::schedule(const std::vector<Outgoing>& frames, std::uint64_t destination) {
  for (const Outgoing& frame : frames) {
    scheduled_.push(Scheduled{frame.due, next_sequence_++, destination, frame.message});
  }
}

int SimHost::poll_timeout_ms(TimePoint now, std::optional<TimePoint> timer) const {
  std::optional<TimePoint> next =
      replay_ ? replay_->next_unsolicited_at() : hands_.next_unsolicited_at();
  if (!scheduled_.empty() && (!next || scheduled_.top().due < *next)) next = scheduled_.top().due;
  if (timer && (!next || *timer < *next)) next = timer;
  if (!next) return kMaxPollMs;
  if (*next <= now) return 0;
  // Round up: waking early would only spin until the frame is due.
  const auto wait = std::chrono::ceil<std::chrono::milliseconds>(*next - now).count();
  return static_cast<int>(std::min<std::int64_t>(wait, kMaxPollMs));
}

void SimHost::read_control(SimTransport& transport) {
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
        spdlog::warn("dh3-sim: control channel: {}", errno_text(errno));
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
    answer_control(execute(line, transport));
    if (stop_requested_.load()) return;
  }
  if (control_buffer_.size() > kMaxControlLine) {
    control_buffer_.clear();
    answer_control("error line too long");
  }
}

void SimHost::answer_control(const std::string& line) {
  if (options_.control_out >= 0) write_all(options_.control_out, line + "\n");
}

SimHand* SimHost::hand_now(std::uint8_t id) {
  SimHand* hand = hands_.find(id);
  if (hand == nullptr) return nullptr;
  schedule(hand->advance(clock_.now()), kEveryPeer);
  return hand;
}

std::string SimHost::execute(std::string_view command, SimTransport& transport) {
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
  if (verb == "hands" && words.size() == 1) {
    std::string answer = "ok hands";
    // Appended, not "literal" + std::string: GCC 12 warns falsely about that at -O3
    // (-Wrestrict inside libstdc++'s string insert, GCC bugs 105329, 105651).
    for (const std::uint8_t id : ids()) answer.append(" ").append(std::to_string(id));
    return answer;
  }
  if (verb == "violations" && words.size() == 1) {
    if (!watch_.enabled()) return "error the interval check is off (start with --min-interval-ms)";
    return "ok " + std::to_string(watch_.violations());
  }
  if (std::optional<std::string> answer = transport.execute_own(words)) return *answer;
  return execute_for_hand(words, echo);
}

std::string SimHost::execute_for_hand(std::span<const std::string_view> words,
                                      const std::string& echo) {
  const std::string_view verb = words[0];
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
  if (replay_) return "error replaying a recording: the hands do what it says";
  const auto id = dh3::parse_hand_id(words[1]);
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
    return describe_state(*hand);
  } else if (verb == "object" || verb == "obstacle") {
    const auto place = parse_place(words[2]);
    if (!place) return "error " + place.error();
    if (verb == "object") {
      hand->place_object(*place);
    } else {
      hand->place_rotation_obstacle(*place);
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
