#pragma once
// The service's way back to its clients: the reply and group reply writers,
// each behind its ReplyGate (reply_gate.hpp), and the writers' match listeners
// that let a client's held replies go when its reply reader matches.
//
// Thread-safe: replies from bus loops and request listeners, matches from Fast
// DDS listener threads, expiry from the timer; writes under no lock of its own.

#include <cstddef>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "dh3/base/clock.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/dds/request_trace_seam.hpp"
#include "reply_gate.hpp"
#include "reply_sink.hpp"

namespace dh3::dds {

class ReplyChannel final : public ReplySink {
 public:
  /// `on_held`: a reply was held; its deadline may be the timer's next.
  ReplyChannel(const Clock& clock, const RequestTracer& tracer, std::function<void()> on_held);
  ReplyChannel(const ReplyChannel&) = delete;
  ReplyChannel& operator=(const ReplyChannel&) = delete;

  /// The listeners to create the writers with (publication_matched).
  [[nodiscard]] eprosima::fastdds::dds::DataWriterListener* reply_listener() {
    return &reply_listener_;
  }
  [[nodiscard]] eprosima::fastdds::dds::DataWriterListener* group_reply_listener() {
    return &group_reply_listener_;
  }
  /// Each set once at set-up, before the requests that its replies answer
  /// can arrive; null: that kind of reply is dropped.
  void set_reply_writer(eprosima::fastdds::dds::DataWriter* writer) { writer_ = writer; }
  void set_group_reply_writer(eprosima::fastdds::dds::DataWriter* writer) {
    group_writer_ = writer;
  }
  /// Takes the listeners off the writers and forgets them (before they are deleted).
  void detach();

  /// Writes the reply, or leaves it with the gate until the client's reply
  /// reader has matched (`reply` is then moved from).
  void write(msg::CommandReply& reply) override;
  void write(msg::GroupReply& reply) override;

  void participant_joined(const std::string& client_id);
  /// Drops the replies held for a participant that left; returns how many.
  /// Logs how many of its replies the hold caps dropped, if any.
  std::size_t participant_left(const std::string& client_id);
  /// Replies the gates' hold caps dropped since the start (reply_gate.hpp).
  [[nodiscard]] std::size_t dropped_replies() const;

  /// The earliest time a held reply must go out anyway.
  [[nodiscard]] std::optional<TimePoint> next_expiry() const;
  /// Writes the replies held past the limit (the timer's job).
  void write_expired();
  /// Writes every held reply now (stop).
  void write_all_held();

  /// How long a reply waits for its client's reply reader to match before it
  /// is written anyway: as long as a client waits for a reply at most.
  static constexpr Duration kHoldLimit = std::chrono::milliseconds(limits::REQUEST_TIMEOUT_MAX_MS);
  /// How many replies each gate holds (reply_gate.hpp says why these).
  static constexpr HoldCaps kHoldCaps{};

 private:
  /// A reply writer's matches: writes the replies a match frees. Fast DDS
  /// calls it without the writer's locks, and it takes only the gate's.
  class WriterListener final : public eprosima::fastdds::dds::DataWriterListener {
   public:
    WriterListener(ReplyChannel& channel, bool group) : channel_(channel), group_(group) {}
    void on_publication_matched(
        eprosima::fastdds::dds::DataWriter* writer,
        const eprosima::fastdds::dds::PublicationMatchedStatus& status) override;

   private:
    ReplyChannel& channel_;
    bool group_;
  };

  /// Writes past the gate.
  void publish(msg::CommandReply& reply);
  void publish(msg::GroupReply& reply);
  /// What write() does for either kind of reply (defined in the .cpp only).
  template <typename Reply>
  void pass_through(Reply& reply, ReplyGate<Reply>& gate, bool has_writer, std::string_view what);
  /// The first drop of each client, in words.
  static void log_dropped(const DroppedReply& dropped, std::string_view what);

  const RequestTracer& tracer_;
  std::function<void()> on_held_;
  ReplyGate<msg::CommandReply> gate_;
  ReplyGate<msg::GroupReply> group_gate_;
  WriterListener reply_listener_{*this, false};
  WriterListener group_reply_listener_{*this, true};
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;        ///< set before start
  eprosima::fastdds::dds::DataWriter* group_writer_ = nullptr;  ///< set before start
};

}  // namespace dh3::dds
