#include "client_rate.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>

namespace dh3::dds {

Result<void, std::string> ClientRate::admit(const std::string& caller_id,
                                            const std::string& shown_as) {
  if (rate_ == 0) return {};
  const TimePoint now = clock_.now();
  std::lock_guard lock(mutex_);
  auto [it, added] = buckets_.try_emplace(caller_id);
  Bucket& bucket = it->second;
  if (added) {
    bucket.requests = rate_;
  } else {
    const double seconds = std::chrono::duration<double>(now - bucket.filled).count();
    bucket.requests = std::min<double>(rate_, bucket.requests + seconds * rate_);
  }
  bucket.filled = now;
  if (bucket.requests >= 1) {
    bucket.requests -= 1;
    bucket.warned = false;
    return {};
  }
  ++refused_;
  std::string message = "client '" + shown_as + "' (participant " + caller_id +
                        ") sends more than " + std::to_string(rate_) +
                        " requests a second; at most " + std::to_string(rate_) +
                        " per client (client_rate_limit): send fewer";
  // Once per time over its rate: a flood would log a line per request.
  if (!bucket.warned) spdlog::warn("{}", message);
  bucket.warned = true;
  return fail(std::move(message));
}

void ClientRate::forget(const std::string& caller_id) {
  std::lock_guard lock(mutex_);
  buckets_.erase(caller_id);
}

std::uint64_t ClientRate::refused() const {
  std::lock_guard lock(mutex_);
  return refused_;
}

}  // namespace dh3::dds
