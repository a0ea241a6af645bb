// A request names the service incarnation it is for (request_address.hpp):
// what a client writes, and what a service takes for an address.

#include <gtest/gtest.h>

#include "dh3/contract/participant.hpp"
#include "dh3/contract/request_address.hpp"

namespace dh3::contract {
namespace {

namespace rtps = eprosima::fastrtps::rtps;

rtps::GuidPrefix_t prefix(rtps::octet first) {
  rtps::GuidPrefix_t p;
  for (std::size_t i = 0; i < rtps::GuidPrefix_t::size; ++i) {
    p.value[i] = static_cast<rtps::octet>(first + i);
  }
  return p;
}

eprosima::fastdds::dds::SampleInfo written_with(const rtps::WriteParams& params) {
  eprosima::fastdds::dds::SampleInfo info;
  info.related_sample_identity = params.related_sample_identity();
  return info;
}

TEST(RequestAddress, ARequestNamesTheParticipantItIsFor) {
  const auto service = prefix(0x10);
  const auto params = addressed_to(client_id_for(service));
  EXPECT_EQ(params.related_sample_identity().writer_guid(),
            rtps::GUID_t(service, rtps::c_EntityId_RTPSParticipant));
  EXPECT_FALSE(addressed_elsewhere(written_with(params), service));
  EXPECT_TRUE(addressed_elsewhere(written_with(params), prefix(0x20)));
}

TEST(RequestAddress, WhatIsNoParticipantsIdLeavesTheRequestUnaddressed) {
  for (const char* id : {"", "0123", "zz23456789abcdef01234567", "000000000000000000000000"}) {
    const auto params = addressed_to(id);
    EXPECT_EQ(params.related_sample_identity(), rtps::SampleIdentity()) << id;
    EXPECT_FALSE(addressed_elsewhere(written_with(params), prefix(0x20))) << id;
  }
}

TEST(RequestAddress, AnotherUseOfTheRelatedIdentityIsNoAddress) {
  // A request-reply peer that names its reply reader there (as ROS 2 does).
  eprosima::fastdds::dds::SampleInfo info;
  info.related_sample_identity.writer_guid(rtps::GUID_t(prefix(0x30), rtps::EntityId_t(0x1207)));
  EXPECT_FALSE(addressed_elsewhere(info, prefix(0x20)));
}

}  // namespace
}  // namespace dh3::contract
