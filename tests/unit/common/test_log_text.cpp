// dh3/base/log_text.hpp: text from the network as it may stand in a log line.

#include <gtest/gtest.h>

#include "dh3/base/log_text.hpp"

namespace dh3 {
namespace {

TEST(LogText, EscapesWhatCouldForgeALineOrDriveATerminal) {
  EXPECT_EQ(escaped_for_log("/api/hands"), "/api/hands");
  EXPECT_EQ(escaped_for_log("dh3ctl@cell-pc"), "dh3ctl@cell-pc");
  EXPECT_EQ(escaped_for_log("/x\n127.0.0.1 GET /forged\r"), "/x\\x0a127.0.0.1 GET /forged\\x0d");
  EXPECT_EQ(escaped_for_log("\x1b[2J\x7f\xc3\xa9"), "\\x1b[2J\\x7f\\xc3\\xa9");
  EXPECT_EQ(escaped_for_log("back\\slash"), "back\\x5cslash");
  EXPECT_EQ(escaped_for_log(std::string_view("a\0b", 3)), "a\\x00b");
}

}  // namespace
}  // namespace dh3
