// StandbyBus: a standby's bus hears everything and says nothing until it is
// promoted.

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "dh3/bus/standby_bus.hpp"

namespace dh3::bus {
namespace {

/// A backend that sends into a list and receives what the test put on the line.
class LineBus final : public Bus {
 public:
  const std::string& spec() const override { return spec_; }
  Result<void, BusError> send(const CanFrame& frame) override {
    sent.push_back(frame);
    return {};
  }
  Result<void, BusError> receive(std::vector<CanFrame>& out, Duration) override {
    out.insert(out.end(), on_line.begin(), on_line.end());
    on_line.clear();
    return {};
  }
  void wake() override {}
  LinkState link_state() const override { return LinkState::up; }

  std::vector<CanFrame> sent;
  std::vector<CanFrame> on_line;

 private:
  std::string spec_ = "line";
};

const CanFrame kPositionWrite{1, 8, {0x06, 0x02, 0x01, 0x00, 0x3C, 0, 0, 0}};
const CanFrame kGripStatusRead{2, 8, {0x0F, 0x01, 0, 0, 0, 0, 0, 0}};

struct StandbyBusTest : ::testing::Test {
  StandbyBusTest() {
    auto owned = std::make_unique<LineBus>();
    line = owned.get();
    bus = std::make_unique<StandbyBus>(std::move(owned));
  }
  LineBus* line = nullptr;
  std::unique_ptr<StandbyBus> bus;
};

TEST_F(StandbyBusTest, SendsNothingBeforeItIsPromoted) {
  const auto sent = bus->send(kPositionWrite);
  ASSERT_FALSE(sent);
  EXPECT_EQ(sent.error(), BusError::not_permitted);
  const std::vector<CanFrame> burst{kPositionWrite, kGripStatusRead};
  const auto burst_sent = bus->send_burst(burst);
  ASSERT_FALSE(burst_sent);
  EXPECT_EQ(burst_sent.error(), BusError::not_permitted);
  EXPECT_TRUE(line->sent.empty());
  EXPECT_EQ(bus->refused(), 3u);
  EXPECT_FALSE(bus->promoted());
}

TEST_F(StandbyBusTest, HearsEveryFrameOnTheLineWhileSilent) {
  line->on_line = {kPositionWrite, kPositionWrite, kGripStatusRead};
  std::vector<CanFrame> heard;
  ASSERT_TRUE(bus->receive(heard, Duration::zero()));
  EXPECT_EQ(heard, (std::vector<CanFrame>{kPositionWrite, kPositionWrite, kGripStatusRead}));
  EXPECT_TRUE(line->sent.empty());
}

TEST_F(StandbyBusTest, SendsOncePromoted) {
  ASSERT_FALSE(bus->send(kGripStatusRead));
  bus->promote();
  EXPECT_TRUE(bus->promoted());
  ASSERT_TRUE(bus->send(kPositionWrite));
  const std::vector<CanFrame> burst{kGripStatusRead, kGripStatusRead};
  const auto taken = bus->send_burst(burst);
  ASSERT_TRUE(taken);
  EXPECT_EQ(taken.value(), 2u);
  EXPECT_EQ(line->sent,
            (std::vector<CanFrame>{kPositionWrite, kGripStatusRead, kGripStatusRead}));
  EXPECT_EQ(bus->refused(), 1u);  // the one refused before promotion, not resent
}

}  // namespace
}  // namespace dh3::bus
