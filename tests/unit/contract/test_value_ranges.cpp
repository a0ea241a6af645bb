// The contract's value limits (idl/dh3.idl, module dh3::limits, as
// idl/include/dh3/contract/value_ranges.hpp maps them to commands) and the protocol layer's
// register map are two declarations of one fact: each command's range must be
// the range of the register it writes. A limit changed in one and not the
// other fails here.
#include <gtest/gtest.h>

#include "dh3/contract/value_ranges.hpp"
#include "dh3/protocol/registers.hpp"

namespace dh3 {
namespace {

namespace reg = protocol::reg;

struct CommandWrites {
  msg::CommandType command;
  protocol::Register written;
};

TEST(ContractValueRanges, EachCommandTakesTheRangeOfTheRegisterItWrites) {
  const CommandWrites commands[] = {
      {msg::MOVE, reg::kPosition},
      {msg::RELEASE, reg::kPosition},
      {msg::ROTATE, reg::kRotation},
      {msg::SET_CLOSING_FORCE, reg::kClosingForce},
      {msg::SET_OPENING_FORCE, reg::kOpeningForce},
      {msg::GRASP, reg::kClosingForce},
      {msg::SET_CAN_ID, reg::kCanId},
      {msg::SET_BAUD_RATE, reg::kBaudRate},
  };
  for (const auto& [command, written] : commands) {
    SCOPED_TRACE(contract::command_name(command));
    const auto contract_range = contract::value_range(command);
    const auto register_range = protocol::write_range(written);
    ASSERT_TRUE(contract_range.has_value());
    ASSERT_TRUE(register_range.has_value());
    EXPECT_EQ(contract_range->min, register_range->min);
    EXPECT_EQ(contract_range->max, register_range->max);
  }
}

TEST(ContractValueRanges, TheBaudIndexRangeIsTheProtocolsTableOfRates) {
  const auto range = protocol::write_range(reg::kBaudRate);
  ASSERT_TRUE(range.has_value());
  for (std::int32_t index = range->min; index <= range->max; ++index) {
    EXPECT_TRUE(protocol::baud_index_to_bps(index).has_value()) << index;
  }
  EXPECT_FALSE(protocol::baud_index_to_bps(range->max + 1).has_value());
  EXPECT_EQ(limits::BAUD_INDEX_MAX, range->max);
}

}  // namespace
}  // namespace dh3
