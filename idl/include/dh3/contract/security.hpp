#pragma once
// Switches DDS Security on for a participant: the properties of
// dh3/contract/security_files.hpp added to its QoS.
//
//   const auto files = dh3::contract::security_files_in(dir, "service");
//   if (auto readable = dh3::contract::check_security_files(files); !readable) {
//     return fail(readable.error());
//   }
//   auto qos = dh3::contract::participant_qos(name, transport);
//   dh3::contract::enable_security(qos, files);

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

#include "dh3/contract/security_files.hpp"

namespace dh3::contract {

/// Adds the security properties to the participant's QoS. Check the files
/// first (check_security_files); Fast DDS refuses to create a participant
/// whose credentials do not load or do not fit together.
void enable_security(eprosima::fastdds::dds::DomainParticipantQos& qos, const SecurityFiles& files);

}  // namespace dh3::contract
