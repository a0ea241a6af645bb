// participant_names.hpp: a participant is shown by the name it announces, which
// is its own claim: what it holds besides printable text is escaped, so that a
// name cannot forge a line of the service's log or of a console.

#include <gtest/gtest.h>

#include <fastdds/rtps/attributes/RTPSParticipantAllocationAttributes.hpp>

#include "participant_names.hpp"

namespace dh3::dds {
namespace {

namespace rtps = eprosima::fastrtps::rtps;

std::string shown_for(const std::string& announced) {
  rtps::ParticipantProxyData data{rtps::RTPSParticipantAllocationAttributes()};
  data.m_participantName = announced;
  return shown_name(data);
}

TEST(ParticipantNames, AnAnnouncedNameIsShownAsItIs) {
  EXPECT_EQ(shown_for("dh3ctl@cell-pc"), "dh3ctl@cell-pc");
}

TEST(ParticipantNames, ANameCannotForgeALogLine) {
  EXPECT_EQ(shown_for("x\n2026-01-01 00:00:00.000 info bus0/1: lease taken by 'admin'"),
            "x\\x0a2026-01-01 00:00:00.000 info bus0/1: lease taken by 'admin'");
  EXPECT_EQ(shown_for("\x1b[31mred"), "\\x1b[31mred");
}

}  // namespace
}  // namespace dh3::dds
