#pragma once
// A ReplySink that keeps what it is given, for the request side's unit tests.

#include <vector>

#include "reply_sink.hpp"

namespace dh3::dds {

class RecordingReplySink final : public ReplySink {
 public:
  void write(msg::CommandReply& reply) override { replies.push_back(reply); }
  void write(msg::GroupReply& reply) override { group_replies.push_back(reply); }

  std::vector<msg::CommandReply> replies;
  std::vector<msg::GroupReply> group_replies;
};

}  // namespace dh3::dds
