// idl/include/dh3/contract/cell_partition.hpp: the partition a service publishes its cell in,
// and which names get none (DDS would read them as patterns).

#include <gtest/gtest.h>

#include "dh3/contract/cell_partition.hpp"

namespace dh3::contract {
namespace {

TEST(CellPartition, IsTheServicesNameUnderTheDh3Prefix) {
  EXPECT_EQ(cell_partition("cell01"), "dh3.cell.cell01");
  EXPECT_EQ(cell_partition("press line 2"), "dh3.cell.press line 2");
  EXPECT_NE(cell_partition("a"), cell_partition("b"));
}

TEST(CellPartition, ANameDdsWouldReadAsAPatternHasNone) {
  // fnmatch patterns: "cell*" would match every cell's partition.
  for (const char* name : {"cell*", "cell?", "cell[12]", "cell\\1", ""}) {
    EXPECT_EQ(cell_partition(name), std::nullopt) << name;
  }
}

}  // namespace
}  // namespace dh3::contract
