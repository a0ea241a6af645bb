#include "dh3/contract/reply_filter.hpp"

#include <cstring>
#include <optional>
#include <utility>

#include "serialized_string.hpp"
#include "unquoted.hpp"

namespace dh3::contract {

namespace {

/// The one parameter, unquoted; nullopt if there is not exactly one.
std::optional<std::string> client_id_of(const FilterParameters& parameters) {
  if (parameters.length() != 1 || parameters[0] == nullptr) return std::nullopt;
  return unquoted(parameters[0]);
}

}  // namespace

std::string own_replies_topic_name() {
  return "dh3/command_reply/own";
}

bool serialized_client_id(const unsigned char* data, std::uint32_t length,
                          std::string_view& client_id) {
  // The first member, right after the 4 bytes of encapsulation.
  std::uint32_t offset = 4;
  return read_serialized_string(data, length, offset, client_id);
}

ReplyFilter::ReplyFilter(std::string client_id, ReplyFilterCounts& counts)
    : client_id_(std::move(client_id)), counts_(counts) {}

std::unique_ptr<ReplyFilter> ReplyFilter::make(const char* expression,
                                               const FilterParameters& parameters,
                                               ReplyFilterCounts& counts) {
  if (std::strcmp(expression, kReplyFilterExpression) != 0) return nullptr;
  auto client_id = client_id_of(parameters);
  if (!client_id) return nullptr;
  return std::make_unique<ReplyFilter>(std::move(*client_id), counts);
}

bool ReplyFilter::set_parameters(const FilterParameters& parameters) {
  auto client_id = client_id_of(parameters);
  if (!client_id) return false;
  client_id_ = std::move(*client_id);
  return true;
}

bool ReplyFilter::evaluate(const SerializedPayload& payload,
                           const FilterSampleInfo& /*sample_info*/,
                           const GUID_t& /*reader_guid*/) const {
  std::string_view client_id;
  // A sample it cannot read goes through: the client checks client_id again.
  const bool pass =
      !serialized_client_id(payload.data, payload.length, client_id) || client_id == client_id_;
  counts_.count(pass);
  return pass;
}

eprosima::fastdds::dds::ContentFilteredTopic* create_own_replies_topic(
    eprosima::fastdds::dds::DomainParticipant& participant,
    eprosima::fastdds::dds::Topic* reply_topic, const std::string& client_id) {
  if (reply_topic == nullptr) return nullptr;
  return participant.create_contentfilteredtopic(own_replies_topic_name(), reply_topic,
                                                 kReplyFilterExpression, {client_id},
                                                 kReplyFilterClass);
}

}  // namespace dh3::contract
