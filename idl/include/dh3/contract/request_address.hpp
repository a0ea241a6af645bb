#pragma once
// Which incarnation of a service a request is for. A client writes each
// request for the owner it believes, naming that participant in the sample's
// related_sample_identity (DataWriter::write with WriteParams): the writer
// GUID is that participant's own GUID, its sequence number unknown. A service
// serves a request that names its own participant or none (a client of
// another vendor, or built from an older contract; an identity that is not a
// participant's is not an address); it drops one that names another
// participant. So a request written to an owner that has since died is never
// carried out by the standby that took over: neither one the client wrote
// just before it saw the takeover, nor one DDS brought to the standby late
// (repaired after a lost datagram), which the dead owner may have carried out
// already. The client ends such a call SERVICE_LOST (docs/hot-standby.md).

#include <fastdds/rtps/common/WriteParams.h>

#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/rtps/common/GuidPrefix_t.hpp>
#include <string>

namespace dh3::contract {

/// WriteParams that address a request to the participant `participant_id`
/// (its GUID prefix in hex, client_id_for); unaddressed if that is not one.
[[nodiscard]] eprosima::fastrtps::rtps::WriteParams addressed_to(const std::string& participant_id);

/// The request `info` describes names a participant other than `own`.
[[nodiscard]] bool addressed_elsewhere(const eprosima::fastdds::dds::SampleInfo& info,
                                       const eprosima::fastrtps::rtps::GuidPrefix_t& own);

}  // namespace dh3::contract
