#pragma once
// Following one cell: a client that follows a service (or one bus of it)
// reads the status, event and service-info topics through content-filtered
// topics of dh3's own filter class, and every service's writers evaluate the
// same filter for each such reader, so a client is sent only its cell's
// samples: what it receives and spends does not grow with the plant. Like the
// reply filter (dh3_reply_filter.hpp, which says when Fast DDS 2.9 filters on
// the writer's side), this one reads the first members of the serialized
// sample in place, without deserializing it: HandStatus and HandEvent begin
// with the hand's service and bus (HandEvent's HandAddress is its first
// member, and @final types travel as plain CDR, with no header of their own),
// ServiceInfo with its service. A reader of the plain topics, e.g. a
// participant of another vendor, still gets everything.
//
// Where a writer does not filter for a reader, the reader filters what
// arrives: samples a writer kept from before the reader matched (Fast DDS
// evaluates a writer's filters only for the readers matched when a sample is
// written: a follower that joins is sent each hand's last status once), and
// writers that do not know the class.

#include <atomic>
#include <cstdint>
#include <cstring>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "dh3/base/result.hpp"
#include "dh3_idl/dh3.h"

namespace dh3::contract {

/// The filter class, as readers announce it in discovery.
inline constexpr const char* kFollowFilterClass = "DH3_FOLLOW";
/// The expressions the class accepts: %0 is the service, %1 the bus.
inline constexpr const char* kFollowServiceExpression = "service = %0";
inline constexpr const char* kFollowBusExpression = "service = %0 AND bus = %1";

/// What a client follows: one service, or one bus of it (bus empty: every bus).
struct Follow {
  std::string service;
  std::string bus;
  [[nodiscard]] std::string to_string() const { return bus.empty() ? service : service + "/" + bus; }
};

/// Why a name cannot be followed; empty if it can. Names are what a service
/// and its buses are called: 1 to MAX_NAME_LENGTH printable characters, no
/// '/' (it separates them), no quote (DDSSQL quotes parameters with it).
[[nodiscard]] inline std::string follow_name_problem(std::string_view name) {
  if (name.empty()) return "an empty name";
  if (name.size() > limits::MAX_NAME_LENGTH) {
    return "a name longer than " + std::to_string(limits::MAX_NAME_LENGTH) + " characters";
  }
  for (const char c : name) {
    if (c == '/' || c == '\'' || static_cast<unsigned char>(c) <= ' ' || c == 0x7f) {
      return "a name with a space, a control character, a quote or a '/'";
    }
  }
  return {};
}

/// "SERVICE" or "SERVICE/BUS"; fails with a message that says what is wrong.
[[nodiscard]] inline Result<Follow, std::string> parse_follow(std::string_view text) {
  const auto bad = [&](const std::string& why) {
    return fail("cannot follow '" + std::string(text) + "': " + why +
                " (give SERVICE or SERVICE/BUS)");
  };
  Follow follow;
  const auto slash = text.find('/');
  follow.service = std::string(text.substr(0, slash));
  if (slash != std::string_view::npos) {
    follow.bus = std::string(text.substr(slash + 1));
    if (follow.bus.find('/') != std::string::npos) return bad("more than SERVICE/BUS");
    if (auto problem = follow_name_problem(follow.bus); !problem.empty()) {
      return bad("the bus is " + problem);
    }
  }
  if (auto problem = follow_name_problem(follow.service); !problem.empty()) {
    return bad("the service is " + problem);
  }
  return follow;
}

/// Reads the CDR string at `offset` (aligned to 4 past the 4-byte
/// encapsulation) of a plain CDR payload, without copying, and moves `offset`
/// past it; false if the payload is not plain CDR or too short.
[[nodiscard]] inline bool read_serialized_string(const unsigned char* data, std::uint32_t length,
                                                 std::uint32_t& offset, std::string_view& text) {
  // 4 bytes of encapsulation (CDR_BE 0x0000, CDR_LE 0x0001), then the members;
  // CDR aligns from the end of the encapsulation. A string: a 4-byte length
  // counting its terminating NUL, then its bytes.
  constexpr std::uint32_t kHeader = 4;
  if (data == nullptr || length < kHeader || data[0] != 0) return false;
  const bool little_endian = data[1] == 1;
  if (!little_endian && data[1] != 0) return false;
  offset = kHeader + ((offset - kHeader + 3U) & ~3U);
  if (offset > length || length - offset < 4) return false;
  const unsigned char* size_bytes = data + offset;
  const std::uint32_t size =
      little_endian ? (std::uint32_t{size_bytes[0]} | std::uint32_t{size_bytes[1]} << 8U |
                       std::uint32_t{size_bytes[2]} << 16U | std::uint32_t{size_bytes[3]} << 24U)
                    : (std::uint32_t{size_bytes[3]} | std::uint32_t{size_bytes[2]} << 8U |
                       std::uint32_t{size_bytes[1]} << 16U | std::uint32_t{size_bytes[0]} << 24U);
  if (size == 0 || size > length - offset - 4) return false;
  text = std::string_view(reinterpret_cast<const char*>(size_bytes + 4), size - 1);
  offset += 4 + size;
  return true;
}

/// The service and, when `bus` is given, the bus a serialized HandStatus or
/// HandEvent (or, service only, ServiceInfo) is about; false if it cannot be read.
[[nodiscard]] inline bool serialized_service_bus(const unsigned char* data, std::uint32_t length,
                                                 std::string_view& service,
                                                 std::string_view* bus) {
  std::uint32_t offset = 4;
  if (!read_serialized_string(data, length, offset, service)) return false;
  return bus == nullptr || read_serialized_string(data, length, offset, *bus);
}

/// Counts what the follow filters of one participant decided: on a service,
/// its writers' (writer-side filtering); on a client, its readers', i.e. the
/// samples that reached it although a writer did not filter them for it.
struct FollowFilterCounts {
  std::atomic<std::uint64_t> passed{0};
  std::atomic<std::uint64_t> rejected{0};
};

// Fast DDS's filter interfaces have no virtual destructor; a filter is only
// ever deleted as a FollowFilter (FollowFilterFactory::delete_content_filter).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"
class FollowFilter final : public eprosima::fastdds::dds::IContentFilter {
 public:
  FollowFilter(Follow follow, FollowFilterCounts& counts)
      : follow_(std::move(follow)), counts_(counts) {}
  void set_follow(Follow follow) { follow_ = std::move(follow); }
  [[nodiscard]] const Follow& follow() const { return follow_; }

  /// Whether the sample is about the followed service (and bus).
  [[nodiscard]] bool matches(const unsigned char* data, std::uint32_t length) const {
    std::string_view service;
    std::string_view bus;
    const bool with_bus = !follow_.bus.empty();
    // A sample it cannot read goes through: the reader's type rejects it.
    if (!serialized_service_bus(data, length, service, with_bus ? &bus : nullptr)) return true;
    return service == follow_.service && (!with_bus || bus == follow_.bus);
  }

  bool evaluate(const SerializedPayload& payload, const FilterSampleInfo& /*sample_info*/,
                const GUID_t& /*reader_guid*/) const override {
    const bool pass = matches(payload.data, payload.length);
    (pass ? counts_.passed : counts_.rejected).fetch_add(1, std::memory_order_relaxed);
    return pass;
  }

 private:
  Follow follow_;
  FollowFilterCounts& counts_;
};

/// Makes FollowFilters; registered under kFollowFilterClass on every dh3
/// participant (it must outlive the participant).
class FollowFilterFactory final : public eprosima::fastdds::dds::IContentFilterFactory {
 public:
  /// The Follow a filter expression and its parameters describe; nullopt if
  /// malformed (an unknown expression, parameters that do not fit it, a name
  /// that cannot be followed). `expression` nullptr: new parameters for a
  /// filter made with `with_bus`.
  [[nodiscard]] static std::optional<Follow> follow_of(const char* expression,
                                                       const ParameterSeq& parameters,
                                                       bool with_bus = false) {
    if (expression != nullptr) {
      if (std::strcmp(expression, kFollowBusExpression) == 0) {
        with_bus = true;
      } else if (std::strcmp(expression, kFollowServiceExpression) == 0) {
        with_bus = false;
      } else {
        return std::nullopt;
      }
    }
    if (parameters.length() != (with_bus ? 2 : 1)) return std::nullopt;
    Follow follow;
    for (ParameterSeq::size_type i = 0; i < parameters.length(); ++i) {
      if (parameters[i] == nullptr) return std::nullopt;
      std::string name = unquoted(parameters[i]);
      if (!follow_name_problem(name).empty()) return std::nullopt;
      (i == 0 ? follow.service : follow.bus) = std::move(name);
    }
    return follow;
  }

  ReturnCode_t create_content_filter(
      const char* /*filter_class_name*/, const char* /*type_name*/,
      const eprosima::fastdds::dds::TopicDataType* /*data_type*/, const char* filter_expression,
      const ParameterSeq& filter_parameters,
      eprosima::fastdds::dds::IContentFilter*& filter_instance) override {
    if (filter_expression == nullptr) {  // new parameters for an existing filter
      if (filter_instance == nullptr) return ReturnCode_t::RETCODE_BAD_PARAMETER;
      auto* filter = static_cast<FollowFilter*>(filter_instance);
      auto follow = follow_of(nullptr, filter_parameters, !filter->follow().bus.empty());
      if (!follow) return ReturnCode_t::RETCODE_BAD_PARAMETER;
      filter->set_follow(std::move(*follow));
      return ReturnCode_t::RETCODE_OK;
    }
    auto follow = follow_of(filter_expression, filter_parameters);
    if (!follow) return ReturnCode_t::RETCODE_BAD_PARAMETER;
    delete_content_filter(nullptr, filter_instance);
    filter_instance = new FollowFilter(std::move(*follow), counts_);
    return ReturnCode_t::RETCODE_OK;
  }

  ReturnCode_t delete_content_filter(
      const char* /*filter_class_name*/,
      eprosima::fastdds::dds::IContentFilter* filter_instance) override {
    delete static_cast<FollowFilter*>(filter_instance);
    return ReturnCode_t::RETCODE_OK;
  }

  [[nodiscard]] const FollowFilterCounts& counts() const { return counts_; }

 private:
  /// DDSSQL spells a string parameter 'quoted'; accept that spelling too.
  static std::string unquoted(std::string_view text) {
    if (text.size() >= 2 && text.front() == '\'' && text.back() == '\'') {
      text = text.substr(1, text.size() - 2);
    }
    return std::string(text);
  }
  FollowFilterCounts counts_;
};
#pragma GCC diagnostic pop

/// `topic` as a follower of `follow` reads it (named "<topic>/follow"): the
/// hand topics by service and bus, the service info by service. nullptr if
/// Fast DDS refused (e.g. no FollowFilterFactory registered).
inline eprosima::fastdds::dds::ContentFilteredTopic* create_follow_topic(
    eprosima::fastdds::dds::DomainParticipant& participant, eprosima::fastdds::dds::Topic* topic,
    const Follow& follow, bool by_bus) {
  if (topic == nullptr) return nullptr;
  const bool with_bus = by_bus && !follow.bus.empty();
  std::vector<std::string> parameters{follow.service};
  if (with_bus) parameters.push_back(follow.bus);
  return participant.create_contentfilteredtopic(
      topic->get_name() + "/follow", topic,
      with_bus ? kFollowBusExpression : kFollowServiceExpression, parameters, kFollowFilterClass);
}

}  // namespace dh3::contract
