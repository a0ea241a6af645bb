// What dh3ctl prints: JSON one object per line that scripts can parse
// (client_json.hpp, which dh3-web prints too), and tables and lines people can read.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client_json.hpp"
#include "output.hpp"

namespace dh3::ctl {
namespace {

using ::testing::EndsWith;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

template <typename T>
std::string to_json(const T& value) {
  return json_text(Json(value));
}
std::string json_string(std::string_view text) {
  return json_text(Json(text));
}

TEST(JsonTest, StringsAreEscaped) {
  EXPECT_EQ(json_string("plain"), "\"plain\"");
  EXPECT_EQ(json_string("a \"quote\" and \\ back"), R"("a \"quote\" and \\ back")");
  EXPECT_EQ(json_string("line\nbreak\ttab"), R"("line\nbreak\ttab")");
  EXPECT_EQ(json_string(std::string("nul\0x", 5)), R"("nul\u0000x")");
  EXPECT_EQ(json_string("\x1b[H"), R"("\u001b[H")");
  EXPECT_EQ(json_string("Grüße"), "\"Grüße\"");  // UTF-8 passes through
}

TEST(JsonTest, TextThatIsNotUtf8IsPrintedNotRefused) {
  EXPECT_EQ(json_string("bad \xff byte"), "\"bad \xEF\xBF\xBD byte\"");
}

TEST(JsonTest, ObjectKeepsMembersInOrder) {
  const Json o{
      {"s", "x"}, {"i", std::int32_t{-3}}, {"b", false}, {"ids", std::vector<std::uint16_t>{1, 2}}};
  EXPECT_EQ(json_text(o), R"({"s":"x","i":-3,"b":false,"ids":[1,2]})");
  EXPECT_EQ(json_text(Json::object()), "{}");
}

TEST(JsonTest, ReplyObjectSaysCodeMessageAndWhatTheCommandReturned) {
  Reply grasp;
  grasp.grasp = GraspOutcome::missed;
  grasp.value = 0;
  EXPECT_EQ(json_text(reply_json("grasp", "cell/bus0/1", grasp)),
            R"({"type":"reply","command":"grasp","hand":"cell/bus0/1","ok":true,"code":"OK",)"
            R"("message":"","value":0,"grasp":"MISSED","position":0})");

  Reply denied;
  denied.code = Code::denied;
  denied.message = "hand 1 is leased by client 'x'";
  denied.lease_holder = "x";
  const std::string line = json_text(reply_json("move", "cell/bus0/1", denied));
  EXPECT_THAT(line, HasSubstr(R"("ok":false,"code":"DENIED")"));
  EXPECT_THAT(line, HasSubstr(R"("message":"hand 1 is leased by client 'x'")"));
  EXPECT_THAT(line, HasSubstr(R"("lease_holder":"x")"));
  EXPECT_THAT(line, Not(HasSubstr("\n")));

  Reply scan;
  scan.found_ids = {1, 2, 3};
  EXPECT_THAT(json_text(reply_json("scan", "cell/bus0", scan)),
              HasSubstr(R"("found_ids":[1,2,3])"));
  EXPECT_THAT(json_text(reply_json("scan", "cell/bus0", Reply{})), HasSubstr(R"("found_ids":[])"));
  EXPECT_THAT(json_text(reply_json("move", "cell/bus0/1", Reply{})), Not(HasSubstr("found_ids")));
}

HandStatus sample_status() {
  HandStatus s;
  s.address = {"cell", "bus0", 1};
  s.name = "left";
  s.online = true;
  s.initialized = true;
  s.grip = GripState::grasped;
  s.position = 42;
  s.target_position = 0;
  s.closing_force = 40;
  s.opening_force = 50;
  s.rotation = 10;
  s.update_seq = 7;
  return s;
}

TEST(JsonTest, StatusObjectIsOneLineWithEveryField) {
  const std::string line = to_json(sample_status());
  EXPECT_THAT(line, StartsWith(R"({"type":"status","hand":"cell/bus0/1","service":"cell",)"));
  EXPECT_THAT(line, HasSubstr(R"("grip":"GRASPED","position":42,"target_position":0)"));
  EXPECT_THAT(line, HasSubstr(R"("online":true,"initialized":true)"));
  EXPECT_THAT(line, HasSubstr(R"("update_seq":7)"));
  EXPECT_THAT(line, Not(HasSubstr("\n")));
}

TEST(JsonTest, ValuesNotReadYetAreNullAndDashesNeverMinusOne) {
  auto s = sample_status();
  s.position = -1;
  s.rotation = -1;
  s.rotation_target = -1;
  s.closing_force = -1;
  const std::string line = to_json(s);
  EXPECT_THAT(line, HasSubstr(R"("position":null)"));
  EXPECT_THAT(line, HasSubstr(R"("rotation":null,"rotation_target":null)"));
  EXPECT_THAT(line, HasSubstr(R"("closing_force":null)"));
  EXPECT_THAT(line, Not(HasSubstr("-1")));
  EXPECT_THAT(status_line(s), HasSubstr("position - target 0"));
  EXPECT_THAT(status_line(s), HasSubstr("force -/50 rotation -"));
  EXPECT_THAT(status_line(s), Not(HasSubstr("-1")));
}

TEST(JsonTest, StatusSaysWhenItsValuesWereRead) {
  auto s = sample_status();
  s.read_at_ns = 1'700'000'000'123'000'000ULL;
  EXPECT_THAT(to_json(s), HasSubstr(R"("read_at_ns":1700000000123000000)"));
  // Text: the time of day it was read, with milliseconds; "-" before any answer.
  EXPECT_THAT(status_line(s), HasSubstr(".123"));
  EXPECT_THAT(status_line(sample_status()), HasSubstr(" read -"));
  EXPECT_THAT(status_table({s}), HasSubstr("READ"));
}

TEST(JsonTest, EventAndServiceObjects) {
  HandEvent e;
  e.hand = {"cell", "bus0", 2};
  e.kind = EventKind::grasped;
  e.message = "caught";
  EXPECT_THAT(to_json(e), HasSubstr(R"("type":"event","hand":"cell/bus0/2")"));
  EXPECT_THAT(to_json(e), HasSubstr(R"("kind":"GRASPED")"));
  EXPECT_THAT(to_json(e), HasSubstr(R"("position":null)")) << "where it stopped, not read yet";
  e.position = 40;
  EXPECT_THAT(to_json(e), HasSubstr(R"("position":40)"));
  // The value beside it, under the name of what it is.
  e.value = 55;
  EXPECT_THAT(to_json(e), HasSubstr(R"("closing_force":55)"));
  e.kind = EventKind::online;
  e.value = 0x04010200;
  EXPECT_THAT(to_json(e), HasSubstr(R"("firmware_version":67174912)"));
  EXPECT_THAT(to_json(e), HasSubstr(R"("firmware_version_text":"4.1.2.0")"));
  e.kind = EventKind::fault;
  EXPECT_THAT(to_json(e), Not(HasSubstr("firmware")));

  ServiceInfo info;
  info.name = "cell";
  info.ready = true;
  info.buses.push_back(BusInfo{"bus0", "sim:1,2", true, {{1, "left"}, {2, ""}}});
  EXPECT_THAT(to_json(info),
              HasSubstr(R"("buses":[{"name":"bus0","spec":"sim:1,2","link_up":true,)"
                        R"("hands":[{"can_id":1,"name":"left"},{"can_id":2,"name":""}]}])"));
}

TEST(TextTest, StatusTableAlignsColumnsUnderTheHeader) {
  auto second = sample_status();
  second.address.can_id = 12;
  second.name.clear();
  second.online = false;
  second.service_lost = true;
  second.position = -1;
  second.last_error = Code::timeout;
  second.last_error_message = "no answer";
  const std::string table = status_table({sample_status(), second});
  std::vector<std::string> lines;
  for (std::size_t at = 0; at < table.size();) {
    const auto end = table.find('\n', at);
    lines.push_back(table.substr(at, end - at));
    at = end + 1;
  }
  ASSERT_EQ(lines.size(), 3U);
  EXPECT_THAT(lines[0], StartsWith("HAND"));
  // Every column starts at the same offset in every line.
  const auto column = [](const std::string& line, std::size_t n) {
    std::size_t at = 0;
    for (std::size_t i = 0; i < n; ++i) {
      at = line.find_first_not_of(' ', line.find(' ', at));
    }
    return at;
  };
  for (std::size_t c = 1; c < 6; ++c) {
    EXPECT_EQ(column(lines[0], c), column(lines[1], c)) << "column " << c;
    EXPECT_EQ(column(lines[0], c), column(lines[2], c)) << "column " << c;
  }
  EXPECT_THAT(lines[1], HasSubstr("GRASPED"));
  EXPECT_THAT(lines[1], HasSubstr("40/50"));
  EXPECT_THAT(lines[2], HasSubstr("lost"));
  EXPECT_THAT(lines[2], HasSubstr("TIMEOUT: no answer"));
  // A configured hand that never answered says so, not just "no".
  second.service_lost = false;
  second.read_at_ns = 0;
  EXPECT_THAT(status_table({second}), HasSubstr("never answered"));
  EXPECT_THAT(status_line(second), HasSubstr("offline (never answered)"));
}

TEST(TextTest, EventAndServiceLines) {
  HandEvent e;
  e.hand = {"cell", "bus0", 2};
  e.name = "right";
  e.kind = EventKind::dropped;
  e.position = 55;
  e.message = "object lost";
  EXPECT_EQ(event_line(e), "cell/bus0/2 (right) DROPPED position 55 target 0: object lost");
  e.kind = EventKind::arrived;
  e.position.reset();
  e.target = 30;
  e.value = 2;
  e.message.clear();
  EXPECT_EQ(event_line(e), "cell/bus0/2 (right) ARRIVED position - (not read yet) target 30");
  // The value in words where it says what the kind does not.
  e.kind = EventKind::grasped;
  e.position = 40;
  e.value = 60;
  EXPECT_EQ(event_line(e), "cell/bus0/2 (right) GRASPED position 40 target 30 force 60");
  e.kind = EventKind::online;
  e.value = 0x04010200;
  EXPECT_THAT(event_line(e), EndsWith(" ONLINE position 40 target 30 firmware 4.1.2.0"));
  e.kind = EventKind::offline;
  e.value = 3;
  EXPECT_THAT(event_line(e),
              EndsWith(" OFFLINE position 40 target 30 after 3 unanswered requests"));
  e.value = 0;
  EXPECT_THAT(event_line(e), EndsWith(" OFFLINE position 40 target 30"));

  ServiceInfo info;
  info.name = "cell";
  info.host = "ctrl";
  info.version = "0.1.0";
  info.ready = true;
  info.buses.push_back(BusInfo{"bus0", "sim:1,2", true, {{1, "left"}, {2, ""}}});
  EXPECT_EQ(service_line(info),
            "cell on ctrl (version 0.1.0, admin refused): bus0 sim:1,2 link up, hands 1(left) 2");
  EXPECT_THAT(status_line(sample_status()),
              HasSubstr("cell/bus0/1 (left) online initialized position 42"));
}

}  // namespace
}  // namespace dh3::ctl
