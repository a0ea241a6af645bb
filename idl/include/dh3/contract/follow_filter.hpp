#pragma once
// Following one cell: a client that follows a service (or one bus of it)
// reads the status, event and service-info topics through content-filtered
// topics of dh3's own filter class, and every service's writers evaluate the
// same filter for each such reader, so a client is sent only its cell's
// samples: what it receives and spends does not grow with the plant. Like the
// reply filter (dh3/contract/reply_filter.hpp, which says when Fast DDS 2.9 filters on
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

#include <cstdint>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "dh3/base/result.hpp"
#include "dh3/contract/counting_filter_factory.hpp"
#include "dh3/contract/dh3.h"

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
  [[nodiscard]] std::string to_string() const {
    return bus.empty() ? service : service + "/" + bus;
  }
};

/// Why a name cannot be followed; empty if it can. Names are what a service
/// and its buses are called: 1 to MAX_NAME_LENGTH printable characters, no
/// '/' (it separates them), no quote (DDSSQL quotes parameters with it).
[[nodiscard]] std::string follow_name_problem(std::string_view name);

/// "SERVICE" or "SERVICE/BUS"; fails with a message that says what is wrong.
[[nodiscard]] Result<Follow, std::string> parse_follow(std::string_view text);

/// The service and, when `bus` is given, the bus a serialized HandStatus or
/// HandEvent (or, service only, ServiceInfo) is about; false if it cannot be read.
[[nodiscard]] bool serialized_service_bus(const unsigned char* data, std::uint32_t length,
                                          std::string_view& service, std::string_view* bus);

/// Counts what the follow filters of one participant decided: on a service,
/// its writers' (writer-side filtering); on a client, its readers', i.e. the
/// samples that reached it although a writer did not filter them for it.
using FollowFilterCounts = FilterCounts;

// Fast DDS's filter interfaces have no virtual destructor; a filter is only
// ever deleted as a FollowFilter (FollowFilterFactory::delete_content_filter).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"
class FollowFilter final : public eprosima::fastdds::dds::IContentFilter {
 public:
  FollowFilter(Follow follow, FollowFilterCounts& counts);
  /// A filter for kFollowServiceExpression or kFollowBusExpression and the
  /// names they take; nullptr for anything else.
  [[nodiscard]] static std::unique_ptr<FollowFilter> make(const char* expression,
                                                          const FilterParameters& parameters,
                                                          FollowFilterCounts& counts);
  /// New names for the same expression; false if they do not fit it.
  bool set_parameters(const FilterParameters& parameters);
  [[nodiscard]] const Follow& follow() const { return follow_; }

  /// Whether the sample is about the followed service (and bus).
  [[nodiscard]] bool matches(const unsigned char* data, std::uint32_t length) const;

  bool evaluate(const SerializedPayload& payload, const FilterSampleInfo& sample_info,
                const GUID_t& reader_guid) const override;

 private:
  Follow follow_;
  FollowFilterCounts& counts_;
};
#pragma GCC diagnostic pop

/// Registered under kFollowFilterClass on every dh3 participant.
using FollowFilterFactory = CountingFilterFactory<FollowFilter>;

/// `topic` as a follower of `follow` reads it (named "<topic>/follow"): the
/// hand topics by service and bus, the service info by service. nullptr if
/// Fast DDS refused (e.g. no FollowFilterFactory registered).
eprosima::fastdds::dds::ContentFilteredTopic* create_follow_topic(
    eprosima::fastdds::dds::DomainParticipant& participant, eprosima::fastdds::dds::Topic* topic,
    const Follow& follow, bool by_bus);

}  // namespace dh3::contract
