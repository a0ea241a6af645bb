#include "dh3/contract/follow_filter.hpp"

#include <cstring>
#include <utility>
#include <vector>

#include "serialized_string.hpp"
#include "unquoted.hpp"

namespace dh3::contract {

std::string follow_name_problem(std::string_view name) {
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

Result<Follow, std::string> parse_follow(std::string_view text) {
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

bool serialized_service_bus(const unsigned char* data, std::uint32_t length,
                            std::string_view& service, std::string_view* bus) {
  std::uint32_t offset = 4;
  if (!read_serialized_string(data, length, offset, service)) return false;
  return bus == nullptr || read_serialized_string(data, length, offset, *bus);
}

FollowFilter::FollowFilter(Follow follow, FollowFilterCounts& counts)
    : follow_(std::move(follow)), counts_(counts) {}

void FollowFilter::set_follow(Follow follow) {
  follow_ = std::move(follow);
}

bool FollowFilter::matches(const unsigned char* data, std::uint32_t length) const {
  std::string_view service;
  std::string_view bus;
  const bool with_bus = !follow_.bus.empty();
  // A sample it cannot read goes through: the reader's type rejects it.
  if (!serialized_service_bus(data, length, service, with_bus ? &bus : nullptr)) return true;
  return service == follow_.service && (!with_bus || bus == follow_.bus);
}

bool FollowFilter::evaluate(const SerializedPayload& payload,
                            const FilterSampleInfo& /*sample_info*/,
                            const GUID_t& /*reader_guid*/) const {
  const bool pass = matches(payload.data, payload.length);
  counts_.count(pass);
  return pass;
}

std::optional<Follow> FollowFilterFactory::follow_of(const char* expression,
                                                     const ParameterSeq& parameters,
                                                     bool with_bus) {
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

FollowFilterFactory::ReturnCode_t FollowFilterFactory::create_content_filter(
    const char* /*filter_class_name*/, const char* /*type_name*/,
    const eprosima::fastdds::dds::TopicDataType* /*data_type*/, const char* filter_expression,
    const ParameterSeq& filter_parameters,
    eprosima::fastdds::dds::IContentFilter*& filter_instance) {
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

eprosima::fastdds::dds::ContentFilteredTopic* create_follow_topic(
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
