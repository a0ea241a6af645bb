#include "dh3/app/bus_setup.hpp"

#include <spdlog/spdlog.h>

#include "dh3/bus/bus_spec.hpp"
#include "dh3/bus/recording_bus.hpp"
#include "dh3/sim/sim_bus.hpp"

namespace dh3::app {
namespace {

const HandSettings* find_hand(const BusSettings& bus, std::uint8_t id) {
  for (const auto& hand : bus.hands) {
    if (hand.id == id) return &hand;
  }
  return nullptr;
}

std::unique_ptr<bus::Bus> open_sim_bus(const BusSettings& settings, bus::BusSpec spec,
                                       const Clock& clock) {
  spec.sim_hand_ids = simulated_ids(settings);
  std::vector<sim::SimHandOptions> hands;
  for (const std::uint8_t id : spec.sim_hand_ids) {
    sim::SimHandOptions hand;
    hand.id = id;
    hand.reply_delay = settings.sim.reply_delay;
    hand.position_speed = settings.sim.position_speed;
    hand.rotation_speed = settings.sim.rotation_speed;
    hand.init_time = settings.sim.init_time;
    if (const HandSettings* listed = find_hand(settings, id)) {
      hand.object_position = listed->object;
      hand.rotation_obstacle = listed->rotation_obstacle;
    }
    hands.push_back(hand);
  }
  sim::SimBusOptions options;
  options.bit_rate = settings.sim.bit_rate;
  return std::make_unique<sim::SimBus>(bus::to_string(spec), std::move(hands), clock, options);
}

/// `opened` with its flight recorder, when the bus has one.
Result<std::unique_ptr<bus::Bus>, std::string> with_recorder(const BusSettings& settings,
                                                             std::unique_ptr<bus::Bus> opened) {
  if (!settings.record) return opened;
  auto recorder = bus::FrameRecorder::start(settings.name, *settings.record);
  if (!recorder) return fail("bus '" + settings.name + "': flight recorder: " + recorder.error());
  spdlog::info("bus '{}': recording every frame into {}/{}.NNNNNN.log (at most {} files of {} "
               "bytes)",
               settings.name, settings.record->dir.string(), (*recorder)->device(),
               settings.record->max_files, settings.record->max_file_bytes);
  return std::unique_ptr<bus::Bus>(
      std::make_unique<bus::RecordingBus>(std::move(opened), std::move(*recorder)));
}

}  // namespace

std::vector<std::uint8_t> simulated_ids(const BusSettings& bus) {
  if (is_bare_sim_spec(bus.spec) && !bus.hands.empty()) {
    std::vector<std::uint8_t> ids;
    for (const auto& hand : bus.hands) ids.push_back(hand.id);
    return ids;
  }
  auto spec = bus::parse_bus_spec(bus.spec);
  return spec ? spec->sim_hand_ids : std::vector<std::uint8_t>{};
}

std::vector<hand::HandConfig> expected_hands(const BusSettings& bus) {
  std::vector<hand::HandConfig> hands;
  for (const auto& hand : bus.hands) hands.push_back({hand.id, hand.name});
  if (hands.empty() && bus::is_simulated(bus.spec)) {
    for (const std::uint8_t id : simulated_ids(bus)) hands.push_back({id, {}});
  }
  return hands;
}

Result<std::vector<dds::BusSetup>, std::string> open_buses(const ServiceConfig& config,
                                                           const Clock& clock) {
  std::vector<dds::BusSetup> setups;
  for (const auto& settings : config.buses) {
    auto spec = bus::parse_bus_spec(settings.spec);
    if (!spec) return fail("bus '" + settings.name + "': " + spec.error());
    dds::BusSetup setup;
    setup.name = settings.name;
    setup.hands = expected_hands(settings);
    setup.scheduler = settings.scheduler;
    setup.scheduler.allow_admin = config.allow_admin;
    setup.scheduler.interval_margin =
        settings.interval_margin.value_or(default_interval_margin(settings.spec));
    std::unique_ptr<bus::Bus> opened;
    if (spec->kind == bus::BusKind::sim) {
      opened = open_sim_bus(settings, std::move(*spec), clock);
    } else {
      bus::OpenBusOptions options;
      options.socketcan.bit_rate = settings.bit_rate;
      options.socketcan.receive_timestamps = settings.record.has_value();
      options.transfer_box.can_bit_rate = settings.bit_rate;
      auto backend = bus::open_bus(*spec, clock, options);
      if (!backend) return fail("bus '" + settings.name + "': " + backend.error());
      opened = std::move(*backend);
    }
    auto recorded = with_recorder(settings, std::move(opened));
    if (!recorded) return fail(recorded.error());
    setup.bus = std::move(*recorded);
    setups.push_back(std::move(setup));
  }
  return setups;
}

}  // namespace dh3::app
