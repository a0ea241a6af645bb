#include "dh3/hand/hand_roster.hpp"

namespace dh3::hand {
namespace {

/// The fields a status sample shows (not its sequence or time).
bool same_published_fields(const HandState& a, const HandState& b) {
  return a.can_id == b.can_id && a.name == b.name && a.online == b.online &&
         a.initialized == b.initialized && a.grip == b.grip && a.position == b.position &&
         a.target_position == b.target_position && a.closing_force == b.closing_force &&
         a.opening_force == b.opening_force && a.rotation == b.rotation &&
         a.rotation_target == b.rotation_target && a.rotation_state == b.rotation_state &&
         a.firmware_version == b.firmware_version && a.last_error == b.last_error &&
         a.last_error_message == b.last_error_message;
}

}  // namespace

bool HandRoster::differs_from_published(const HandState& state) const {
  std::lock_guard lock(published_mutex_);
  const auto& published = published_[state.can_id];
  return !published || !same_published_fields(state, *published);
}

void HandRoster::publish(const HandState& state) {
  std::lock_guard lock(published_mutex_);
  published_[state.can_id] = state;
}

std::vector<HandState> HandRoster::published() const {
  std::lock_guard lock(published_mutex_);
  std::vector<HandState> out;
  for (const auto& state : published_) {
    if (state) out.push_back(*state);
  }
  return out;
}

}  // namespace dh3::hand
