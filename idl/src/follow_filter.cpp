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

namespace {

/// The Follow a filter expression and its parameters describe; nullopt if
/// malformed (an unknown expression, parameters that do not fit it, a name
/// that cannot be followed). `expression` nullptr: new parameters for a
/// filter made with `with_bus`.
std::optional<Follow> follow_of(const char* expression, const FilterParameters& parameters,
                                bool with_bus = false) {
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
  for (FilterParameters::size_type i = 0; i < parameters.length(); ++i) {
    if (parameters[i] == nullptr) return std::nullopt;
    std::string name = unquoted(parameters[i]);
    if (!follow_name_problem(name).empty()) return std::nullopt;
    (i == 0 ? follow.service : follow.bus) = std::move(name);
  }
  return follow;
}

}  // namespace

std::unique_ptr<FollowFilter> FollowFilter::make(const char* expression,
                                                 const FilterParameters& parameters,
                                                 FollowFilterCounts& counts) {
  auto follow = follow_of(expression, parameters);
  if (!follow) return nullptr;
  return std::make_unique<FollowFilter>(std::move(*follow), counts);
}

bool FollowFilter::set_parameters(const FilterParameters& parameters) {
  auto follow = follow_of(nullptr, parameters, !follow_.bus.empty());
  if (!follow) return false;
  follow_ = std::move(*follow);
  return true;
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
