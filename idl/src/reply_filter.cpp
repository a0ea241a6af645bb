#include "dh3/contract/reply_filter.hpp"

#include <cstring>
#include <utility>

#include "serialized_string.hpp"
#include "unquoted.hpp"

namespace dh3::contract {

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

void ReplyFilter::set_client_id(std::string client_id) {
  client_id_ = std::move(client_id);
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

ReplyFilterFactory::ReturnCode_t ReplyFilterFactory::create_content_filter(
    const char* /*filter_class_name*/, const char* /*type_name*/,
    const eprosima::fastdds::dds::TopicDataType* /*data_type*/, const char* filter_expression,
    const ParameterSeq& filter_parameters,
    eprosima::fastdds::dds::IContentFilter*& filter_instance) {
  if (filter_parameters.length() != 1 || filter_parameters[0] == nullptr) {
    return ReturnCode_t::RETCODE_BAD_PARAMETER;
  }
  std::string client_id = unquoted(filter_parameters[0]);
  if (filter_expression == nullptr) {  // new parameters for an existing filter
    if (filter_instance == nullptr) return ReturnCode_t::RETCODE_BAD_PARAMETER;
    static_cast<ReplyFilter*>(filter_instance)->set_client_id(std::move(client_id));
    return ReturnCode_t::RETCODE_OK;
  }
  if (std::strcmp(filter_expression, kReplyFilterExpression) != 0) {
    return ReturnCode_t::RETCODE_BAD_PARAMETER;
  }
  delete_content_filter(nullptr, filter_instance);
  filter_instance = new ReplyFilter(std::move(client_id), counts_);
  return ReturnCode_t::RETCODE_OK;
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
