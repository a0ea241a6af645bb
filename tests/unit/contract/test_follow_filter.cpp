// idl/include/dh3/contract/follow_filter.hpp: what a client may follow, how the filter reads
// the service and bus of serialized statuses, events and service infos, what
// it lets through, and the expressions and parameters its factory accepts.

#include <gtest/gtest.h>

#include <fastdds/dds/core/LoanableSequence.hpp>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/contract/dh3PubSubTypes.h"
#include "dh3/contract/follow_filter.hpp"

namespace {

using dh3::contract::Follow;
using dh3::contract::FollowFilter;
using dh3::contract::FollowFilterCounts;
using dh3::contract::FollowFilterFactory;
using dh3::contract::parse_follow;
using eprosima::fastrtps::types::ReturnCode_t;
namespace fdds = eprosima::fastdds::dds;

/// A sample as Fast DDS serializes it.
template <typename PubSubType, typename T>
std::vector<unsigned char> serialized(T sample) {
  PubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&sample)());
  EXPECT_TRUE(type.serialize(&sample, &payload));
  return {payload.data, payload.data + payload.length};
}

std::vector<unsigned char> status_of(const std::string& service, const std::string& bus) {
  dh3::msg::HandStatus status;
  status.service(service);
  status.bus(bus);
  status.can_id(3);
  status.name("left");
  return serialized<dh3::msg::HandStatusPubSubType>(status);
}

std::vector<unsigned char> event_of(const std::string& service, const std::string& bus) {
  dh3::msg::HandEvent event;
  event.hand().service(service);
  event.hand().bus(bus);
  event.hand().can_id(2);
  event.message("after the address");
  return serialized<dh3::msg::HandEventPubSubType>(event);
}

std::vector<unsigned char> info_of(const std::string& service) {
  dh3::msg::ServiceInfo info;
  info.service(service);
  info.version("1.0");  // the second string: a bus filter must not read it as a bus
  return serialized<dh3::msg::ServiceInfoPubSubType>(info);
}

bool passes(const Follow& follow, const std::vector<unsigned char>& bytes) {
  FollowFilterCounts counts;
  const FollowFilter filter(follow, counts);
  return filter.matches(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
}

TEST(FollowFilter, ParsesAServiceOrAServiceAndBus) {
  auto service = parse_follow("cell01");
  ASSERT_TRUE(service) << service.error();
  EXPECT_EQ(service->service, "cell01");
  EXPECT_EQ(service->bus, "");
  auto bus = parse_follow("cell01/left");
  ASSERT_TRUE(bus) << bus.error();
  EXPECT_EQ(bus->service, "cell01");
  EXPECT_EQ(bus->bus, "left");
  EXPECT_EQ(bus->to_string(), "cell01/left");
}

TEST(FollowFilter, RefusesWhatNamesNoServiceOrBusSayingWhy) {
  for (const char* text :
       {"", "/", "/bus0", "cell01/", "cell01/bus0/3", "cell 01", "cell01/bu's", "cell\t1"}) {
    auto parsed = parse_follow(text);
    ASSERT_FALSE(parsed) << "'" << text << "' was accepted";
    EXPECT_NE(parsed.error().find("cannot follow '" + std::string(text) + "'"), std::string::npos)
        << parsed.error();
    EXPECT_NE(parsed.error().find("SERVICE or SERVICE/BUS"), std::string::npos) << parsed.error();
  }
  const std::string long_name(dh3::limits::MAX_NAME_LENGTH + 1, 'c');
  auto too_long = parse_follow(long_name);
  ASSERT_FALSE(too_long);
  EXPECT_NE(too_long.error().find("longer than"), std::string::npos) << too_long.error();
  EXPECT_TRUE(parse_follow(std::string(dh3::limits::MAX_NAME_LENGTH, 'c')));
}

TEST(FollowFilter, ReadsServiceAndBusOfSerializedStatusesAndEvents) {
  for (const auto& bytes : {status_of("cell01", "bus0"), event_of("cell01", "bus0")}) {
    std::string_view service;
    std::string_view bus;
    ASSERT_TRUE(dh3::contract::serialized_service_bus(
        bytes.data(), static_cast<std::uint32_t>(bytes.size()), service, &bus));
    EXPECT_EQ(service, "cell01");
    EXPECT_EQ(bus, "bus0");
  }
  // The second string is aligned to 4 after the first: "c" (length 2) ends
  // at byte 10, "bus0" starts at 12.
  std::vector<unsigned char> little{0,    1, 0, 0, 2, 0,   0,   0,   'c', 0, 0xee,
                                    0xee, 5, 0, 0, 0, 'b', 'u', 's', '0', 0};
  std::vector<unsigned char> big{0,    0, 0, 0, 0, 0,   0,   2,   'c', 0, 0xee,
                                 0xee, 0, 0, 0, 5, 'b', 'u', 's', '0', 0};
  for (const auto& bytes : {little, big}) {
    std::string_view service;
    std::string_view bus;
    ASSERT_TRUE(dh3::contract::serialized_service_bus(
        bytes.data(), static_cast<std::uint32_t>(bytes.size()), service, &bus));
    EXPECT_EQ(service, "c");
    EXPECT_EQ(bus, "bus0");
  }
}

TEST(FollowFilter, PassesTheFollowedServiceOrBusOnly) {
  const Follow cell{"cell01", ""};
  const Follow bus{"cell01", "bus1"};
  EXPECT_TRUE(passes(cell, status_of("cell01", "bus0")));
  EXPECT_TRUE(passes(cell, status_of("cell01", "bus1")));
  EXPECT_FALSE(passes(cell, status_of("cell02", "bus0")));
  EXPECT_FALSE(passes(cell, status_of("cell011", "bus0")));  // not a prefix match
  EXPECT_FALSE(passes(cell, event_of("cell02", "bus0")));
  EXPECT_TRUE(passes(cell, event_of("cell01", "bus0")));
  EXPECT_TRUE(passes(bus, status_of("cell01", "bus1")));
  EXPECT_FALSE(passes(bus, status_of("cell01", "bus0")));
  EXPECT_FALSE(passes(bus, event_of("cell01", "bus0")));
  EXPECT_FALSE(passes(bus, status_of("cell02", "bus1")));
  // A service info: by its service only (its topic's filter has no bus).
  EXPECT_TRUE(passes(cell, info_of("cell01")));
  EXPECT_FALSE(passes(cell, info_of("cell02")));
}

TEST(FollowFilter, WhatItCannotReadGoesThroughAndIsCounted) {
  const Follow cell{"cell01", ""};
  auto bytes = status_of("cell02", "bus0");
  // Cut inside the service name; an unknown encapsulation (XCDR2 is 0x0007);
  // a length past the end.
  EXPECT_TRUE(passes(cell, std::vector<unsigned char>(bytes.begin(), bytes.begin() + 9)));
  auto xcdr2 = bytes;
  xcdr2[1] = 7;
  EXPECT_TRUE(passes(cell, xcdr2));
  auto too_long = bytes;
  too_long[4] = 0xff;
  EXPECT_TRUE(passes(cell, too_long));
  std::string_view service;
  EXPECT_FALSE(dh3::contract::serialized_service_bus(nullptr, 0, service, nullptr));

  FollowFilterCounts counts;
  const FollowFilter filter(cell, counts);
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), payload.data);
  payload.length = static_cast<std::uint32_t>(bytes.size());
  EXPECT_FALSE(filter.evaluate(payload, {}, {}));
  auto mine = status_of("cell01", "bus0");
  std::copy(mine.begin(), mine.end(), payload.data);
  payload.length = static_cast<std::uint32_t>(mine.size());
  EXPECT_TRUE(filter.evaluate(payload, {}, {}));
  EXPECT_EQ(counts.passed.load(), 1u);
  EXPECT_EQ(counts.rejected.load(), 1u);
}

/// The factory's answer for an expression and parameters, and the filter it
/// made (deleted with the returned holder).
struct Made {
  FollowFilterFactory factory;
  fdds::IContentFilter* filter = nullptr;
  ReturnCode_t code;
  ~Made() { factory.delete_content_filter(nullptr, filter); }
};

ReturnCode_t make(Made& made, const char* expression, const std::vector<const char*>& parameters) {
  using Size = fdds::LoanableCollection::size_type;
  fdds::LoanableSequence<const char*> seq(static_cast<Size>(parameters.size()));
  seq.length(static_cast<Size>(parameters.size()));
  for (std::size_t i = 0; i < parameters.size(); ++i) seq[static_cast<Size>(i)] = parameters[i];
  made.code = made.factory.create_content_filter(dh3::contract::kFollowFilterClass, "", nullptr,
                                                 expression, seq, made.filter);
  return made.code;
}

TEST(FollowFilter, TheFactoryAcceptsItsTwoExpressionsWithFittingParameters) {
  {
    Made made;
    ASSERT_EQ(make(made, dh3::contract::kFollowServiceExpression, {"'cell01'"}),
              ReturnCode_t::RETCODE_OK);
    ASSERT_NE(made.filter, nullptr);
    EXPECT_EQ(static_cast<FollowFilter*>(made.filter)->follow().service, "cell01");
    // New parameters for the same filter (a reader that changed them).
    ASSERT_EQ(make(made, nullptr, {"cell02"}), ReturnCode_t::RETCODE_OK);
    EXPECT_EQ(static_cast<FollowFilter*>(made.filter)->follow().service, "cell02");
    EXPECT_EQ(make(made, nullptr, {"cell02", "bus0"}), ReturnCode_t::RETCODE_BAD_PARAMETER);
  }
  Made made;
  ASSERT_EQ(make(made, dh3::contract::kFollowBusExpression, {"cell01", "bus0"}),
            ReturnCode_t::RETCODE_OK);
  EXPECT_EQ(static_cast<FollowFilter*>(made.filter)->follow().bus, "bus0");
}

TEST(FollowFilter, TheFactoryRefusesMalformedExpressionsAndParameters) {
  using Case = std::pair<const char*, std::vector<const char*>>;
  const std::vector<Case> cases{
      {"service = %0 OR 1 = 1", {"cell01"}},
      {"bus = %0", {"bus0"}},
      {dh3::contract::kFollowServiceExpression, {}},
      {dh3::contract::kFollowServiceExpression, {"cell01", "bus0"}},
      {dh3::contract::kFollowServiceExpression, {nullptr}},
      {dh3::contract::kFollowServiceExpression, {""}},
      {dh3::contract::kFollowServiceExpression, {"cell/01"}},
      {dh3::contract::kFollowBusExpression, {"cell01"}},
      {dh3::contract::kFollowBusExpression, {"cell01", "bus 0"}},
  };
  for (const auto& [expression, parameters] : cases) {
    Made made;
    EXPECT_EQ(make(made, expression, parameters), ReturnCode_t::RETCODE_BAD_PARAMETER)
        << expression << " with " << parameters.size() << " parameter(s)";
    EXPECT_EQ(made.filter, nullptr);
  }
  Made without_filter;
  EXPECT_EQ(make(without_filter, nullptr, {"cell01"}), ReturnCode_t::RETCODE_BAD_PARAMETER);
}

}  // namespace
