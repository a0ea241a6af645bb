#pragma once
// The services dh3-ros2 serves for one hand, as rmw_fastrtps serves a service
// (RosServiceServer):
// - initialize, std_srvs/srv/Trigger: initializes the hand; `success` and,
//   when it failed, why in `message`;
// - set_forces, rcl_interfaces/srv/SetParameters: the parameters
//   `closing_force` and `opening_force` (PARAMETER_DOUBLE or _INTEGER, in
//   newtons, or percent with JointUnits::raw_percent); one result per
//   parameter. A request with an unknown name, a wrong type or a value out of
//   range sets nothing.
// Each takes the hand's lease for the command and gives it back, like any dh3
// client, and refuses while a goal of dh3-ros2 drives the hand (HandTurn).
// Requests are queued to one thread per hand: a Fast DDS listener never waits
// for the hand.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "dh3/client.hpp"
#include "hand_turn.hpp"
#include "joint_units.hpp"
#include "ros2_interfacesPubSubTypes.h"
#include "ros_service_server.hpp"

namespace dh3::ros2 {

namespace srv = rcl_interfaces::srv::dds_;

/// What a SetParameters request asks of the hand's forces, in percent.
struct ForcesRequest {
  std::optional<std::int32_t> closing;
  std::optional<std::int32_t> opening;
  /// One per parameter, in order: empty when it is fine, else why not.
  std::vector<std::string> refused;

  [[nodiscard]] bool ok() const;
};

/// Reads the request's parameters. Pure.
[[nodiscard]] ForcesRequest forces_of(const srv::SetParameters_Request_& request,
                                      const JointUnits& units);

class HandServices {
 public:
  /// `initialize` and `set_forces` are fully qualified ROS service names.
  HandServices(RosParticipant& participant, Client& client, HandAddress hand,
               const std::string& initialize, const std::string& set_forces, JointUnits units,
               std::shared_ptr<HandTurn> turn);
  ~HandServices();
  HandServices(const HandServices&) = delete;
  HandServices& operator=(const HandServices&) = delete;

  /// Every endpoint exists.
  [[nodiscard]] bool ok() const;

 private:
  struct Outcome {
    bool ok = false;
    std::string message;
  };

  void enqueue(std::function<void()> job);
  void run_jobs();
  /// `command` on the hand with its lease; why not when a goal holds it.
  Outcome with_lease(const std::function<Reply(Hand&)>& command);
  void on_initialize(const RequestId& id);
  void on_set_forces(const srv::SetParameters_Request_& request, const RequestId& id);

  Client& client_;
  HandAddress hand_;
  JointUnits units_;
  std::shared_ptr<HandTurn> turn_;
  std::mutex mutex_;  // jobs_, stopping_
  std::condition_variable wake_;
  std::deque<std::function<void()>> jobs_;
  bool stopping_ = false;
  RosServiceServer<
      std_srvs::srv::dds_::Trigger_Request_, std_srvs::srv::dds_::Trigger_Request_PubSubType,
      std_srvs::srv::dds_::Trigger_Response_, std_srvs::srv::dds_::Trigger_Response_PubSubType>
      initialize_;
  RosServiceServer<srv::SetParameters_Request_, srv::SetParameters_Request_PubSubType,
                   srv::SetParameters_Response_, srv::SetParameters_Response_PubSubType>
      set_forces_;
  std::thread worker_;  // last: it runs on the rest
};

}  // namespace dh3::ros2
