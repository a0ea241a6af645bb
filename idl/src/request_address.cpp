#include "dh3/contract/request_address.hpp"

#include <optional>

#include "dh3/base/hex.hpp"

namespace dh3::contract {
namespace {

namespace rtps = eprosima::fastrtps::rtps;

std::optional<rtps::GuidPrefix_t> prefix_of(const std::string& participant_id) {
  rtps::GuidPrefix_t prefix;
  if (!bytes_from_hex(participant_id, prefix.value)) return std::nullopt;
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
