#include "dh3/contract/request_address.hpp"

#include <cstddef>
#include <optional>

namespace dh3::contract {
namespace {

namespace rtps = eprosima::fastrtps::rtps;

std::optional<int> hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return std::nullopt;
}

std::optional<rtps::GuidPrefix_t> prefix_of(const std::string& participant_id) {
  if (participant_id.size() != 2 * rtps::GuidPrefix_t::size) return std::nullopt;
  rtps::GuidPrefix_t prefix;
  for (std::size_t i = 0; i < rtps::GuidPrefix_t::size; ++i) {
    const auto high = hex_digit(participant_id[2 * i]);
    const auto low = hex_digit(participant_id[2 * i + 1]);
    if (!high || !low) return std::nullopt;
    prefix.value[i] = static_cast<rtps::octet>(*high << 4 | *low);
  }
  return prefix;
}

}  // namespace

rtps::WriteParams addressed_to(const std::string& participant_id) {
  rtps::WriteParams params;
  if (const auto prefix = prefix_of(participant_id);
      prefix && *prefix != rtps::c_GuidPrefix_Unknown) {
    rtps::SampleIdentity identity;
    identity.writer_guid(rtps::GUID_t(*prefix, rtps::c_EntityId_RTPSParticipant));
    params.related_sample_identity(identity);
  }
  return params;
}

bool addressed_elsewhere(const eprosima::fastdds::dds::SampleInfo& info,
                         const rtps::GuidPrefix_t& own) {
  const rtps::GUID_t& named = info.related_sample_identity.writer_guid();
  return named.entityId == rtps::c_EntityId_RTPSParticipant && named.guidPrefix != own;
}

}  // namespace dh3::contract
