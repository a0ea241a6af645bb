#include "line_budget.hpp"

#include <algorithm>
#include <chrono>

namespace dh3::hand {

LineBudget::LineBudget(std::uint32_t bit_rate, double max_line_load) {
  if (bit_rate > 0 && max_line_load > 0.0) {
    // A request and its reply, worst-case bit stuffing, at the allowed load.
    const double seconds =
        2.0 * kWorstCaseBitsPerFrame / static_cast<double>(bit_rate) / max_line_load;
    spacing_ = std::chrono::duration_cast<Duration>(std::chrono::duration<double>(seconds));
  }
}

void LineBudget::used(TimePoint now) {
  if (spacing_ == Duration::zero()) return;
  next_at_ = std::max(next_at_, now - kLineBurst * spacing_) + spacing_;
}

}  // namespace dh3::hand
