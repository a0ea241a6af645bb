#include "joint_units.hpp"

#include <cmath>

namespace dh3::ros2 {

namespace {

constexpr double kFull = 100.0;

std::optional<std::int32_t> percent_of(double value, double at_full) {
  if (!std::isfinite(value)) return std::nullopt;
  const double percent = std::round(value / at_full * kFull);
  if (percent < 0.0 || percent > kFull) return std::nullopt;
  return static_cast<std::int32_t>(percent);
}

}  // namespace

double JointUnits::opening(std::int32_t percent) const {
  return raw_percent ? percent : percent / kFull * opening_max_m;
}

double JointUnits::force(std::int32_t percent) const {
  return raw_percent ? percent : percent / kFull * force_max_n;
}

double JointUnits::rotation(std::int32_t percent) const {
  return raw_percent ? percent
                       : rotation_min_rad + percent / kFull * (rotation_max_rad - rotation_min_rad);
}

std::optional<std::int32_t> JointUnits::opening_percent(double opening) const {
  return percent_of(opening, raw_percent ? kFull : opening_max_m);
}

std::optional<std::int32_t> JointUnits::force_percent(double force) const {
  return percent_of(force, raw_percent ? kFull : force_max_n);
}

}  // namespace dh3::ros2
