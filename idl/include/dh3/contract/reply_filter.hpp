#pragma once
// Replies only to the client that asked. A dh3 client reads the reply topic
// through a content-filtered topic that keeps the replies carrying its
// client_id; the service's reply writer evaluates the same filter for each such
// reader and sends it only its own replies (Fast DDS 2.9 filters on the
// writer's side when the writer's liveliness lease is infinite, its
// writer_resource_limits().reader_filters_allocation.maximum is above 0 (32 by
// default; no limit on dh3's writers, dh3/contract/qos.hpp), the reader is not reached by
// data-sharing (never for dh3's types: their strings are unbounded) and the reader announced no
// multicast locator). A reader on the plain topic, e.g. a participant of another vendor, still gets
// every reply and keeps its own. Where the writer does not filter (as seen in
// tests/unit/contract/test_reply_filter.cpp, a reader in the writer's own process; replies the
// writer kept from before the reader matched) the reader applies the same filter to what it
// receives.
//
// The filter is dh3's own filter class rather than DDSSQL: Fast DDS's DDSSQL
// filter needs the types' TypeObjects and deserializes each sample into a
// DynamicData once per filtered reader, so the service's work per reply would
// grow with the number of clients; this one reads the first member of the
// serialized reply (client_id) and compares bytes. Both sides of a filter
// must know the class: contract::Participant registers it on every dh3
// participant. Where a writer does not know it, the reader filters alone.

#include <cstdint>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <memory>
#include <string>
#include <string_view>

#include "dh3/contract/counting_filter_factory.hpp"

namespace dh3::contract {

/// The filter class, as readers announce it in discovery.
inline constexpr const char* kReplyFilterClass = "DH3_CLIENT_ID";
/// The only expression the class accepts; parameter %0 is the client_id.
inline constexpr const char* kReplyFilterExpression = "client_id = %0";
/// The name of a client's filtered view of the reply topic in its participant.
std::string own_replies_topic_name();

/// The client_id of a serialized CommandReply (or CommandRequest: both begin
/// with it), without copying; false if the payload is not plain CDR or too
/// short to hold it.
[[nodiscard]] bool serialized_client_id(const unsigned char* data, std::uint32_t length,
                                        std::string_view& client_id);

/// Counts what the filters of one participant decided (on the writer's side
/// for a service, on the reader's side for a client), for tests and
/// benchmarks: a client whose replies are filtered by the service never
/// rejects one itself.
using ReplyFilterCounts = FilterCounts;

// Fast DDS's filter interfaces have no virtual destructor; a filter is only
// ever deleted as a ReplyFilter (ReplyFilterFactory::delete_content_filter).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"
class ReplyFilter final : public eprosima::fastdds::dds::IContentFilter {
 public:
  ReplyFilter(std::string client_id, ReplyFilterCounts& counts);
  /// A filter for kReplyFilterExpression and one client_id; nullptr for
  /// anything else.
  [[nodiscard]] static std::unique_ptr<ReplyFilter> make(const char* expression,
                                                         const FilterParameters& parameters,
                                                         ReplyFilterCounts& counts);
  /// A new client_id; false unless there is exactly one.
  bool set_parameters(const FilterParameters& parameters);

  bool evaluate(const SerializedPayload& payload, const FilterSampleInfo& sample_info,
                const GUID_t& reader_guid) const override;

 private:
  std::string client_id_;
  ReplyFilterCounts& counts_;
};
#pragma GCC diagnostic pop

/// Registered under kReplyFilterClass on every dh3 participant.
using ReplyFilterFactory = CountingFilterFactory<ReplyFilter>;

/// The reply topic as `client_id` reads it: only the replies to its requests.
/// nullptr if Fast DDS refused (e.g. no ReplyFilterFactory registered).
eprosima::fastdds::dds::ContentFilteredTopic* create_own_replies_topic(
    eprosima::fastdds::dds::DomainParticipant& participant,
    eprosima::fastdds::dds::Topic* reply_topic, const std::string& client_id);

}  // namespace dh3::contract
