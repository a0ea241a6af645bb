#include "hand_services.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>

#include "dh3/contract/dh3.h"

namespace dh3::ros2 {

namespace {

// rcl_interfaces/msg/ParameterType.
constexpr std::uint8_t kParameterInteger = 2;
constexpr std::uint8_t kParameterDouble = 3;
// The contract's least force (docs/protocol-notes.md reading 4).
constexpr std::int32_t kMinForcePercent = dh3::limits::FORCE_MIN;
constexpr auto kLeaseTtl = std::chrono::seconds(30);
// Requests waiting for the hand; more are refused at once.
constexpr std::size_t kQueueCap = 16;

/// The force percent of one parameter's value, or why not.
Result<std::int32_t, std::string> force_percent_of(const rcl_interfaces::msg::dds_::Parameter_& p,
                                                   const JointUnits& units) {
  double value = 0.0;
  if (p.value().type() == kParameterDouble) {
    value = p.value().double_value();
  } else if (p.value().type() == kParameterInteger) {
    value = static_cast<double>(p.value().integer_value());
  } else {
    return fail(p.name() + " must be a double (type 3) or an integer (type 2)");
  }
  const auto percent = units.force_percent(value);
  if (!percent || *percent < kMinForcePercent) {
    return fail(p.name() + " " + std::to_string(value) + " is out of range (" +
                std::to_string(kMinForcePercent) + "-100 % of the force)");
  }
  return *percent;
}

}  // namespace

bool ForcesRequest::ok() const {
  if (!closing && !opening) return false;
  for (const auto& why : refused) {
    if (!why.empty()) return false;
  }
  return true;
}

ForcesRequest forces_of(const srv::SetParameters_Request_& request, const JointUnits& units) {
  ForcesRequest forces;
  for (const auto& parameter : request.parameters()) {
    std::optional<std::int32_t>* slot = parameter.name() == "closing_force"   ? &forces.closing
                                        : parameter.name() == "opening_force" ? &forces.opening
                                                                              : nullptr;
    if (slot == nullptr) {
      forces.refused.push_back("no parameter " + parameter.name() +
                               " (closing_force, opening_force)");
      continue;
    }
    auto percent = force_percent_of(parameter, units);
    forces.refused.push_back(percent ? std::string() : percent.error());
    if (percent) *slot = *percent;
  }
  return forces;
}

HandServices::HandServices(RosParticipant& participant, Client& client, HandAddress hand,
                           const std::string& initialize, const std::string& set_forces,
                           JointUnits units, std::shared_ptr<HandTurn> turn)
    : client_(client),
      hand_(std::move(hand)),
      units_(units),
      turn_(std::move(turn)),
      initialize_(participant, initialize,
                  [this](const auto& /*request*/, const RequestId& id) {
                    enqueue([this, id] { on_initialize(id); });
                  }),
      set_forces_(participant, set_forces,
                  [this](const srv::SetParameters_Request_& request, const RequestId& id) {
                    enqueue([this, request, id] { on_set_forces(request, id); });
                  }),
      worker_([this] { run_jobs(); }) {}

HandServices::~HandServices() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  worker_.join();
}

bool HandServices::ok() const {
  return initialize_.ok() && set_forces_.ok();
}

void HandServices::enqueue(std::function<void()> job) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    if (jobs_.size() >= kQueueCap) {
      spdlog::warn("dh3-ros2: {}: too many service requests waiting, one dropped",
                   hand_.to_string());
      return;
    }
    jobs_.push_back(std::move(job));
  }
  wake_.notify_one();
}

void HandServices::run_jobs() {
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
    if (stopping_) return;
    auto job = std::move(jobs_.front());
    jobs_.pop_front();
    lock.unlock();
    job();
    lock.lock();
  }
}

HandServices::Outcome HandServices::with_lease(const std::function<Reply(Hand&)>& command) {
  const auto driving = turn_->try_take();
  if (!driving.owns_lock()) {
    return {false, "a goal of dh3-ros2 drives the hand: cancel it or wait for its end"};
  }
  Hand hand = client_.hand(hand_);
  if (auto lease = hand.acquire_lease(kLeaseTtl); !lease) {
    return {false, "lease: " + std::string(to_string(lease.code)) + ": " + lease.message};
  }
  const auto reply = command(hand);
  hand.release_lease();
  if (!reply) return {false, std::string(to_string(reply.code)) + ": " + reply.message};
  return {true, ""};
}

void HandServices::on_initialize(const RequestId& id) {
  const auto outcome = with_lease([](Hand& hand) { return hand.initialize(); });
  std_srvs::srv::dds_::Trigger_Response_ response;
  response.success(outcome.ok);
  response.message(outcome.ok ? "initialized" : outcome.message);
  if (!outcome.ok) spdlog::info("dh3-ros2: {}: initialize: {}", hand_.to_string(), outcome.message);
  initialize_.reply(id, response);
}

void HandServices::on_set_forces(const srv::SetParameters_Request_& request, const RequestId& id) {
  auto forces = forces_of(request, units_);
  Outcome outcome{false, "not set: another parameter of the request was refused"};
  if (forces.ok()) {
    outcome = with_lease([&forces](Hand& hand) {
      // The closing force is always sent: keep the hand's when only the
      // opening force is asked for.
      const auto status = hand.status();
      const auto closing = forces.closing ? *forces.closing : status ? status->closing_force : 0;
      return hand.set_force(closing, forces.opening);
    });
  }
  srv::SetParameters_Response_ response;
  for (std::size_t i = 0; i < request.parameters().size(); ++i) {
    rcl_interfaces::msg::dds_::SetParametersResult_ result;
    const auto& refused = i < forces.refused.size() ? forces.refused[i] : std::string();
    result.successful(outcome.ok);
    result.reason(outcome.ok ? "" : !refused.empty() ? refused : outcome.message);
    response.results().push_back(result);
  }
  if (!outcome.ok) {
    spdlog::info("dh3-ros2: {}: set_forces refused: {}", hand_.to_string(), outcome.message);
  }
  set_forces_.reply(id, response);
}

}  // namespace dh3::ros2
