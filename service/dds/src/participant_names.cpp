#include "participant_names.hpp"

#include <fastrtps/utils/IPLocator.h>

#include "dh3/base/log_text.hpp"
#include "dh3/contract/participant.hpp"

namespace dh3::dds {

namespace rtps = eprosima::fastrtps::rtps;

namespace {

/// The first unicast address the participant announced, empty if none is an IP one.
std::string first_address(const rtps::ParticipantProxyData& data) {
  for (const auto* list : {&data.metatraffic_locators.unicast, &data.default_locators.unicast}) {
    for (const rtps::Locator_t& locator : *list) {
      if (locator.kind == LOCATOR_KIND_UDPv4 || locator.kind == LOCATOR_KIND_TCPv4 ||
          locator.kind == LOCATOR_KIND_UDPv6 || locator.kind == LOCATOR_KIND_TCPv6) {
        return rtps::IPLocator::ip_to_string(locator);
      }
    }
  }
  return {};
}

}  // namespace

std::string shown_name(const rtps::ParticipantProxyData& data) {
  // The participant's own claim: escaped, so that it cannot forge a line of
  // the service's log (a lease taken) or of a console showing the holder.
  std::string shown = escaped_for_log(data.m_participantName.to_string());
  if (shown.empty()) {
    const std::string address = first_address(data);
    shown = address.empty() ? "unnamed participant" : "unnamed participant at " + address;
  }
#if HAVE_SECURITY
  // Announced in discovery and checked by authentication before any of the
  // participant's samples reach us.
  if (const std::string* subject =
          rtps::DataHolderHelper::find_property_value(data.identity_token_, "dds.cert.sn");
      subject != nullptr && !subject->empty()) {
    shown += " (" + escaped_for_log(*subject) + ")";
  }
#endif
  return shown;
}

void ParticipantNames::discovered(const rtps::ParticipantProxyData& data) {
  remember(contract::client_id_for(data.m_guid.guidPrefix), shown_name(data));
}

void ParticipantNames::remember(const std::string& id, std::string shown) {
  std::lock_guard lock(mutex_);
  names_[id] = std::move(shown);
}

void ParticipantNames::forget(const std::string& id) {
  std::lock_guard lock(mutex_);
  names_.erase(id);
}

std::string ParticipantNames::shown_as(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = names_.find(id);
  return it != names_.end() ? it->second : std::string("a participant not yet discovered");
}

}  // namespace dh3::dds
