#include "commands.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <ctime>
#include <functional>
#include <future>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "client_json.hpp"
#include "client_options_cli.hpp"
#include "dh3/base/version.hpp"
#include "dh3/client.hpp"
#include "dh3/motion_end.hpp"
#include "dh3/registers.hpp"
#include "output.hpp"

namespace dh3::ctl {
namespace {

/// The options every command takes: the client's own, bound to the command
/// line as they are (dh3ctl builds no other copy of them), and how it prints.
struct Globals {
  ClientOptions client;
  double timeout_s = 10.0;
  bool json = false;

  /// --timeout: for the service or hand, and for each reply.
  [[nodiscard]] Timeout timeout() const {
    return std::chrono::milliseconds(static_cast<std::int64_t>(timeout_s * 1000.0));
  }
};

/// What one command line asked for, beyond the globals.
struct Args {
  std::string hand;
  std::string target;  ///< scan: SERVICE or SERVICE/BUS
  std::string reg;
  std::int32_t value = 0;
  std::int32_t second = 0;
  bool has_second = false;
  bool watch = false;
  bool wait = false;  ///< move, rotate: until the motion ends
  bool yes = false;
  int count = 0;              ///< events, status --watch: stop after this many lines (0: never)
  std::string group_command;  ///< group: init, move, rotate, grasp, release, force
  std::vector<std::string> hands;           ///< group: the hands
  std::optional<std::int32_t> group_value;  ///< group: --value (--force, --position)
};

struct Context {
  [[nodiscard]] Timeout timeout() const { return globals.timeout(); }

  /// Prints a failure the way every command does; returns the exit code.
  int fail(std::string_view command, std::string_view target, Code code,
           const std::string& message) {
    if (globals.json) {
      Reply reply;
      reply.code = code;
      reply.message = message;
      out << json_text(reply_json(command, target, reply)) << std::endl;
    }
    err << "dh3ctl: " << command;
    if (!target.empty()) err << " " << target;
    err << ": " << to_string(code) << ": " << message << std::endl;
    return kExitFailed;
  }

  /// Prints a reply: `text` on success (or the JSON object), the reason otherwise.
  int report(std::string_view command, std::string_view target, const Reply& reply,
             const std::string& text) {
    if (!reply.ok()) return fail(command, target, reply.code, reply.message);
    if (globals.json) {
      out << json_text(reply_json(command, target, reply)) << std::endl;
    } else {
      out << text << std::endl;
    }
    return kExitOk;
  }

  /// The hand `spec` names. A full SERVICE/BUS/ID needs no lookup unless
  /// `need_status`: the call itself waits for the service, and a bad value is
  /// refused at once instead of after a wait.
  std::optional<Hand> hand(std::string_view command, const std::string& spec,
                           bool need_status = false) {
    if (!need_status) {
      if (auto parsed = parse_hand_spec(spec); parsed && parsed->is_full()) {
        return client.hand(parsed->address());
      }
    }
    auto found = client.wait_for_hand(spec, timeout());
    if (!found) {
      fail(command, spec, found.code(), found.message());
      return std::nullopt;
    }
    return *found;
  }

  /// Waits, a tenth of a second at a time, until `done` or an interrupt.
  void wait_until_interrupted(std::mutex& mutex, std::condition_variable& cv,
                              const std::function<bool()>& done) {
    std::unique_lock lock(mutex);
    while (!interrupted && !done()) cv.wait_for(lock, std::chrono::milliseconds(100));
  }

  Client& client;
  const Globals& globals;
  std::ostream& out;
  std::ostream& err;
  const std::atomic<bool>& interrupted;
};

std::string hex(std::uint32_t value, int digits) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%0*X", digits, value);
  return text;
}

int cmd_list(Context& c) {
  if (auto found = c.client.wait_for_service({}, c.timeout()); !found) {
    return c.fail("list", "", found.code(), found.message());
  }
  c.client.wait_for_statuses(c.timeout());  // what is there after the wait is listed
  const auto services = c.client.services();
  const auto hands = c.client.hands();
  if (c.globals.json) {
    for (const auto& service : services) c.out << json_text(Json(service)) << "\n";
    for (const auto& hand : hands) c.out << json_text(Json(hand)) << "\n";
    c.out << std::flush;
    return kExitOk;
  }
  for (const auto& service : services) c.out << "service " << service_line(service) << "\n";
  c.out << status_table(hands) << std::flush;
  return kExitOk;
}

void print_statuses(Context& c, const std::vector<HandStatus>& hands) {
  if (c.globals.json) {
    for (const auto& hand : hands) c.out << json_text(Json(hand)) << "\n";
  } else {
    c.out << status_table(hands);
  }
  c.out << std::flush;
}

int watch_statuses(Context& c, std::optional<HandAddress> only, int count) {
  const bool redraw = !c.globals.json && ::isatty(STDOUT_FILENO) == 1;
  std::mutex mutex;
  std::condition_variable cv;
  bool changed = true;
  int updates = 0;
  auto subscription = c.client.subscribe_status(
      [&](const HandStatus& status) {
        std::lock_guard lock(mutex);
        ++updates;
        changed = true;
        // Not a terminal: a stream of lines, one per status sample.
        if (!redraw) {
          c.out << (c.globals.json ? json_text(Json(status)) : status_line(status)) << std::endl;
        }
        cv.notify_all();
      },
      only);
  const auto done = [&] { return count > 0 && updates >= count; };
  // Into a pipe the callback prints every sample: nothing to do here but wait.
  if (!redraw) c.wait_until_interrupted(mutex, cv, done);
  while (redraw && !c.interrupted && !done()) {
    c.wait_until_interrupted(mutex, cv, [&] { return changed || done(); });
    std::unique_lock lock(mutex);
    if (!changed) continue;
    changed = false;
    lock.unlock();
    std::vector<HandStatus> hands;
    for (auto& status : c.client.hands()) {
      if (!only || status.address == *only) hands.push_back(std::move(status));
    }
    const std::time_t now = std::time(nullptr);
    char clock[32];
    std::strftime(clock, sizeof clock, "%H:%M:%S", std::localtime(&now));
    // Home and clear, then the table: a redraw, not a scroll.
    c.out << "\033[H\033[2J"
          << "dh3ctl status --watch  domain " << c.globals.client.domain << "  " << clock
          << "  (Ctrl-C to stop)\n\n"
          << status_table(hands) << std::flush;
    // At most ten redraws a second: a moving hand changes faster than anyone reads.
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  subscription.unsubscribe();
  return kExitOk;
}

int cmd_status(Context& c, const Args& a) {
  std::optional<HandAddress> only;
  if (!a.hand.empty()) {
    auto hand = c.hand("status", a.hand, true);
    if (!hand) return kExitFailed;
    only = hand->address();
  } else {
    if (auto found = c.client.wait_for_service({}, c.timeout()); !found) {
      return c.fail("status", "", found.code(), found.message());
    }
    c.client.wait_for_statuses(c.timeout());
  }
  if (a.watch) return watch_statuses(c, only, a.count);
  std::vector<HandStatus> hands;
  if (only) {
    if (auto status = c.client.status(*only)) hands.push_back(*status);
  } else {
    hands = c.client.hands();
  }
  print_statuses(c, hands);
  return kExitOk;
}

int cmd_events(Context& c, const Args& a) {
  std::optional<HandAddress> only;
  std::string which = "every hand";
  if (!a.hand.empty()) {
    auto hand = c.hand("events", a.hand, true);
    if (!hand) return kExitFailed;
    only = hand->address();
    which = only->to_string();
  }
  std::mutex mutex;
  std::condition_variable cv;
  int seen = 0;
  // Events that come before the "watching" line is printed are held back and
  // printed after it, so the line always comes first and nothing is lost.
  bool announced = c.globals.json;
  std::vector<std::string> held;
  auto subscription = c.client.subscribe(
      [&](const HandEvent& event) {
        std::lock_guard lock(mutex);
        if (a.count > 0 && seen >= a.count) return;
        ++seen;
        std::string line = c.globals.json ? json_text(Json(event)) : event_line(event);
        if (!announced) {
          held.push_back(std::move(line));
          return;
        }
        c.out << line << std::endl;
        cv.notify_all();
      },
      only);
  // Events are a stream: only those after the service matched us arrive.
  // Waiting for a ready service means none after this line is missed.
  if (auto found = c.client.wait_for_service(only ? only->service : "", c.timeout()); !found) {
    c.err << "dh3ctl: events: " << found.message() << "; listening anyway" << std::endl;
  }
  // With --json the line goes to stderr, so that stdout stays one JSON object
  // a line while a person or a script still learns that nothing is missed now.
  if (c.globals.json) {
    c.err << "watching events of " << which << " (Ctrl-C to stop)" << std::endl;
  } else {
    std::lock_guard lock(mutex);
    c.out << "watching events of " << which << " (Ctrl-C to stop)" << std::endl;
    for (const std::string& line : held) c.out << line << std::endl;
    held.clear();
    announced = true;
    cv.notify_all();
  }
  c.wait_until_interrupted(mutex, cv, [&] { return a.count > 0 && seen >= a.count; });
  subscription.unsubscribe();
  return kExitOk;
}

int cmd_scan(Context& c, const Args& a) {
  std::string service;
  std::string bus;
  if (!a.target.empty()) {
    const auto slash = a.target.find('/');
    service = a.target.substr(0, slash);
    if (slash != std::string::npos) bus = a.target.substr(slash + 1);
  }
  if (c.client.read_only()) {
    // A scan is a command request too; and without service info a read-only
    // client does not even know the buses.
    return c.fail("scan", a.target, Code::denied,
                  "not permitted to publish command requests (read-only identity)");
  }
  if (auto found = c.client.wait_for_service(service, c.timeout()); !found) {
    return c.fail("scan", a.target, found.code(), found.message());
  }
  struct Job {
    std::string target;
    std::future<Reply> reply;
  };
  std::vector<Job> jobs;
  for (const auto& info : c.client.services()) {
    if (!info.ready || (!service.empty() && info.name != service)) continue;
    for (const auto& b : info.buses) {
      if (!bus.empty() && b.name != bus) continue;
      jobs.push_back(
          Job{info.name + "/" + b.name, c.client.scan_async(info.name, b.name, c.timeout())});
    }
  }
  if (jobs.empty()) {
    return c.fail("scan", a.target, Code::unknown_hand,
                  "no bus '" + bus + "' in service '" + service + "'");
  }
  int exit_code = kExitOk;
  for (auto& job : jobs) {
    const Reply reply = job.reply.get();
    std::string text = job.target + ": found";
    if (reply.found_ids.empty()) text += " no hands";
    for (const auto id : reply.found_ids) text += " " + std::to_string(id);
    if (c.report("scan", job.target, reply, text) != kExitOk) exit_code = kExitFailed;
  }
  return exit_code;
}

/// move and rotate: "moving to N" once the hand took the command; with --wait,
/// then where the motion ended, from its event (or a read of the position when
/// the event went out before the position was read again).
int cmd_motion(Context& c, const std::string& command, const Args& a, Hand& hand) {
  const bool rotation = command == "rotate";
  const std::string target = hand.address().to_string();
  const Timeout t = c.timeout();
  MotionEnd::Rule rule;
  rule.rotation = rotation;
  rule.target = a.value;
  MotionEnd end(rule);
  // Subscribed before the command goes out, so an end that comes fast is not missed.
  Subscription watching;
  if (a.wait) watching = hand.subscribe([&end](const HandEvent& e) { end.offer(e); });
  const Reply reply = rotation ? hand.rotate_to(a.value, t) : hand.move_to(a.value, t);
  const std::string moving = target + ": moving to " + std::to_string(a.value);
  if (!a.wait || !reply.ok()) return c.report(command, target, reply, moving);
  if (!c.globals.json) c.out << moving << std::endl;
  const auto ended = end.wait(std::chrono::steady_clock::now() + t, [&] { return c.interrupted.load(); });
  watching.unsubscribe();
  if (!ended) {
    return c.fail(command, target, Code::timeout,
                  "the motion did not end within the timeout (" + std::to_string(t.count()) + " ms)");
  }
  if (ended->kind == EventKind::offline) {
    return c.fail(command, target, Code::bus_down, "the hand went offline: " + ended->message);
  }
  std::optional<std::int32_t> at = ended->position;
  if (!at) {
    const Reply read = hand.read(rotation ? reg::rotation : reg::position, t);
    if (!read.ok()) return c.fail(command, target, read.code, read.message);
    at = read.value;
  }
  if (c.globals.json) {
    Json json = reply_json(command, target, reply);
    json["outcome"] = ended->kind;
    json["position"] = *at;
    if (!ended->message.empty()) json["outcome_message"] = ended->message;
    c.out << json_text(json) << std::endl;
  } else {
    std::string text = target + ": " + std::string(to_string(ended->kind)) + " at " +
                       std::to_string(*at);
    if (!ended->message.empty()) text += " (" + ended->message + ")";
    c.out << text << std::endl;
  }
  return kExitOk;
}

/// Commands on one hand that send one request and print its reply.
int cmd_hand(Context& c, const std::string& command, const Args& a) {
  auto hand = c.hand(command, a.hand);
  if (!hand) return kExitFailed;
  const std::string target = hand->address().to_string();
  const Timeout t = c.timeout();
  if (command == "init") {
    return c.report(command, target, hand->initialize(t), target + ": initialized");
  }
  if (command == "move" || command == "rotate") return cmd_motion(c, command, a, *hand);
  if (command == "force") {
    std::optional<std::int32_t> opening;
    if (a.has_second) opening = a.second;
    std::string text = target + ": closing force " + std::to_string(a.value);
    if (opening) text += ", opening force " + std::to_string(*opening);
    return c.report(command, target, hand->set_force(a.value, opening, t), text);
  }
  if (command == "grasp") {
    const Reply reply = hand->grasp(a.value, t);
    return c.report(command, target, reply,
                    target + ": " + std::string(to_string(reply.grasp)) + " at position " +
                        std::to_string(reply.value));
  }
  if (command == "release") {
    return c.report(command, target, hand->release(a.value, t),
                    target + ": released to " + std::to_string(a.value));
  }
  if (command == "stop") return c.report(command, target, hand->stop(t), target + ": stopped");
  if (command == "read") {
    const auto code = parse_register(a.reg);
    if (!code) {
      return c.fail(command, target, Code::invalid_argument,
                    "unknown register '" + a.reg + "' (a name such as position, or 0xNNNN)");
    }
    const Reply reply = hand->read(*code, t);
    const auto name = register_name(*code);
    return c.report(command, target, reply,
                    target + ": " + (name.empty() ? std::string() : std::string(name) + " ") + "(" +
                        hex(*code, 4) + ") = " + std::to_string(reply.value));
  }
  if (command == "version") {
    const Reply reply = hand->read(reg::firmware_version, t);
    return c.report(command, target, reply,
                    target + ": firmware " + firmware_version_text(reply.value) + " (raw " +
                        hex(static_cast<std::uint32_t>(reply.value), 8) + ")");
  }
  if (command == "set-can-id") {
    return c.report(command, target, hand->set_can_id(a.value, t),
                    target + ": CAN ID set to " + std::to_string(a.value) +
                        "; reboot the hand for it to take effect");
  }
  if (command == "set-baud") {
    return c.report(command, target, hand->set_baud_rate(a.value, t),
                    target + ": baud rate index set to " + std::to_string(a.value) +
                        "; reboot the hand for it to take effect");
  }
  return c.fail(command, target, Code::invalid_argument, "unknown command");
}

/// A group command's name on the command line, and whether it takes a value.
std::optional<std::pair<GroupCommand, bool>> parse_group_command(const std::string& name) {
  if (name == "init") return std::pair{GroupCommand::initialize, false};
  if (name == "move") return std::pair{GroupCommand::move, true};
  if (name == "rotate") return std::pair{GroupCommand::rotate, true};
  if (name == "grasp") return std::pair{GroupCommand::grasp, true};
  if (name == "release") return std::pair{GroupCommand::release, true};
  if (name == "force") return std::pair{GroupCommand::set_closing_force, true};
  return std::nullopt;
}

/// One command to several hands, together and all or none: one line per hand.
int cmd_group(Context& c, const Args& a) {
  const std::string command = "group " + a.group_command;
  const auto parsed = parse_group_command(a.group_command);
  if (!parsed) {
    return c.fail(command, "", Code::invalid_argument,
                  "not a group command (init, move, rotate, grasp, release, force)");
  }
  if (parsed->second && !a.group_value) {
    return c.fail(command, "", Code::invalid_argument, a.group_command + " needs --value N");
  }
  std::vector<HandAddress> hands;
  for (const std::string& spec : a.hands) {
    auto hand = c.hand(command, spec);
    if (!hand) return kExitFailed;
    hands.push_back(hand->address());
  }
  const GroupReply reply =
      c.client.group(parsed->first, hands, a.group_value.value_or(0), c.timeout());
  if (reply.hands.empty()) return c.fail(command, "", reply.code, reply.message);
  for (const GroupMemberReply& member : reply.hands) {
    const std::string target = member.hand.to_string();
    std::string text = target + ": " + std::string(to_string(member.code));
    if (member.grasp != GraspOutcome::none) {
      text = target + ": " + std::string(to_string(member.grasp)) + " at position " +
             std::to_string(member.value);
    }
    if (c.globals.json) {
      Json line{{"type", "reply"}, {"command", command}};
      line.update(Json(member));
      c.out << json_text(line) << std::endl;
    } else {
      c.out << text << (member.ok() ? "" : ": " + member.message) << std::endl;
    }
  }
  if (!reply.ok()) {
    c.err << "dh3ctl: " << command << ": " << to_string(reply.code) << ": " << reply.message
          << std::endl;
    return kExitFailed;
  }
  return kExitOk;
}

/// The options every command takes (before or after the command).
void declare_global_options(CLI::App& app, Globals& g) {
  app.add_option("-t,--timeout", g.timeout_s,
                 "seconds to wait for the service or hand, and for each reply (default 10)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--json", g.json, "one JSON object per line, for scripts");
  add_client_options(app, g.client);
}

/// Every command, in the order --help lists them; returns force's optional
/// OPEN argument (whether it was given tells "force 50" from "force 50 0").
CLI::Option* declare_commands(CLI::App& app, Args& a) {
  const auto hand_arg = [&a](CLI::App* sub) {
    sub->add_option("HAND", a.hand, "the hand: SERVICE/BUS/ID, BUS/ID, SERVICE/NAME, ID or NAME")
        ->required();
  };
  const auto value_arg = [&a](CLI::App* sub, const char* name, const char* what) {
    sub->add_option(name, a.value, what)->required();
  };

  app.add_subcommand("list", "services and their hands, with the hands' latest status");
  auto* status = app.add_subcommand("status", "latest status of HAND, or of every hand");
  status->add_option("HAND", a.hand, "the hand (default: every hand)");
  status->add_flag("-w,--watch", a.watch,
                   "keep showing statuses: a table redrawn in place on a terminal, one line per "
                   "update otherwise; Ctrl-C to stop");
  status->add_option("--count", a.count, "with --watch: stop after N status updates");
  hand_arg(app.add_subcommand("init", "initialize HAND (replies once it finished)"));
  auto* move = app.add_subcommand(
      "move", "move HAND's fingers to POS percent (100 = open); answers once the hand took it");
  hand_arg(move);
  value_arg(move, "POS", "position, 0-100");
  move->add_flag("--wait", a.wait,
                 "then wait until the fingers stop, and print how (ARRIVED, GRASPED, MISSED) and where");
  auto* rotate = app.add_subcommand(
      "rotate", "rotate HAND to PCT percent of 90 degrees; answers once the hand took it");
  hand_arg(rotate);
  value_arg(rotate, "PCT", "rotation, 0-100");
  rotate->add_flag("--wait", a.wait,
                   "then wait until the rotation stops, and print how (ROTATION_ARRIVED, "
                   "ROTATION_BLOCKED) and where");
  auto* force = app.add_subcommand("force", "set HAND's closing force, and its opening force");
  hand_arg(force);
  value_arg(force, "CLOSE", "closing (gripping) force, 20-100 percent");
  auto* open_opt = force->add_option("OPEN", a.second, "opening force, 20-100 percent");
  auto* grasp = app.add_subcommand("grasp", "close HAND with FORCE: prints GRASPED or MISSED");
  hand_arg(grasp);
  value_arg(grasp, "FORCE", "closing force, 20-100 percent");
  auto* release = app.add_subcommand("release", "open HAND to POS (replies once arrived)");
  hand_arg(release);
  value_arg(release, "POS", "position, 0-100");
  hand_arg(app.add_subcommand("stop", "stop HAND where it is; pending motion is cancelled"));
  auto* events = app.add_subcommand("events", "print events of every hand, or of HAND");
  events->add_option("HAND", a.hand, "the hand (default: every hand)");
  events->add_option("--count", a.count, "stop after N events");
  hand_arg(app.add_subcommand("version", "read HAND's firmware version"));
  auto* scan = app.add_subcommand("scan", "probe buses for hands now");
  scan->add_option("TARGET", a.target, "SERVICE or SERVICE/BUS (default: every bus)");
  auto* read = app.add_subcommand("read", "read one of HAND's registers");
  hand_arg(read);
  read->add_option("REGISTER", a.reg,
                   "a name (position, closing_force, grip_status, can_id, firmware_version, ...) "
                   "or a code such as 0x0602")
      ->required();
  auto* set_id = app.add_subcommand(
      "set-can-id", "administrative: give HAND a new CAN ID (the hand must be rebooted after)");
  hand_arg(set_id);
  value_arg(set_id, "ID", "new CAN ID, 1-255");
  set_id->add_flag("--yes", a.yes, "confirm");
  auto* set_baud = app.add_subcommand(
      "set-baud", "administrative: set HAND's CAN baud rate (the hand must be rebooted after)");
  hand_arg(set_baud);
  value_arg(set_baud, "INDEX", "0 = 500 kbps, 1 = 400, 2 = 250, 3 = 200, 4 = 125, 5 = 100 kbps");
  set_baud->add_flag("--yes", a.yes, "confirm");
  auto* group = app.add_subcommand(
      "group",
      "one command to several hands at once, all or none: their motions start together "
      "(e.g. group grasp cell/bus0/1 cell/bus0/2 --force 50)");
  group->add_option("COMMAND", a.group_command, "init, move, rotate, grasp, release or force")
      ->required();
  group->add_option("HANDS", a.hands, "the hands, each as HAND is given to the other commands")
      ->required();
  group->add_option("-v,--value,--force,--position", a.group_value,
                    "the value: position or rotation 0-100, force 20-100 percent");

  return open_opt;
}

/// The client's options as the command line gave them, under dh3ctl's name
/// and with --timeout the default of its calls. A command about one hand
/// given as SERVICE/BUS/ID needs nothing of the other services: it follows
/// that hand's service unless --follow says otherwise, so in a plant it is
/// not sent every cell's statuses.
ClientOptions client_options(const Globals& g, const Args& a) {
  ClientOptions options = g.client;
  options.participant_name = "dh3ctl";
  options.default_timeout = g.timeout();
  if (options.follow.empty() && !a.hand.empty()) {
    if (auto parsed = parse_hand_spec(a.hand); parsed && parsed->is_full()) {
      options.follow = *parsed->service;
    }
  }
  return options;
}

}  // namespace

int run(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
        const std::atomic<bool>& interrupted) {
  CLI::App app{
      "dh3ctl: drive DH-3 hands on a DDS domain through their dh3-service.\n"
      "HAND is SERVICE/BUS/ID (e.g. cell/bus0/2), BUS/ID, SERVICE/NAME, ID or NAME;\n"
      "the short forms must name exactly one hand."};
  app.name("dh3ctl");
  app.require_subcommand(1);
  app.fallthrough();  // global options after the command too: dh3ctl list --json
  Globals g;
  declare_global_options(app, g);
  app.set_version_flag("--version", kVersion);

  Args a;
  auto* open_opt = declare_commands(app, a);

  if (auto code = parse_command_line(app, argc, argv, out, err)) {
    return *code == 0 ? kExitOk : kExitUsage;
  }
  a.has_second = open_opt->count() > 0;
  const std::string command = app.get_subcommands().front()->get_name();

  if ((command == "set-can-id" || command == "set-baud") && !a.yes) {
    err << "dh3ctl: " << command
        << " changes a setting stored in the hand, which must then be rebooted; add --yes to "
           "confirm"
        << std::endl;
    return kExitUsage;
  }

  Client client(client_options(g, a));
  if (!client.connected()) {
    err << "dh3ctl: " << client.error() << std::endl;
    return kExitFailed;
  }
  Context context{client, g, out, err, interrupted};
  if (command == "list") return cmd_list(context);
  if (command == "status") return cmd_status(context, a);
  if (command == "events") return cmd_events(context, a);
  if (command == "scan") return cmd_scan(context, a);
  if (command == "group") return cmd_group(context, a);
  return cmd_hand(context, command, a);
}

}  // namespace dh3::ctl
