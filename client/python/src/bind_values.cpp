// The value types the client hands out: addresses, replies, statuses, events,
// what services say about themselves, and the Subscription handle.

#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "bindings.hpp"
#include "calls.hpp"
#include "dh3/address.hpp"
#include "dh3/types.hpp"
#include "support.hpp"

namespace dh3::python {

namespace {

using namespace pybind11::literals;

std::string hand_address_repr(const dh3::HandAddress& a) {
  return "HandAddress(service='" + a.service + "', bus='" + a.bus +
         "', can_id=" + std::to_string(a.can_id) + ")";
}

void bind_hand_address(py::module_& m) {
  py::class_<dh3::HandAddress>(m, "HandAddress", "A hand, unique in a DDS domain.")
      .def(py::init([](std::string service, std::string bus, std::uint16_t can_id) {
             return dh3::HandAddress{std::move(service), std::move(bus), can_id};
           }),
           "service"_a, "bus"_a, "can_id"_a)
      .def_readwrite("service", &dh3::HandAddress::service)
      .def_readwrite("bus", &dh3::HandAddress::bus)
      .def_readwrite("can_id", &dh3::HandAddress::can_id)
      .def("__str__", &dh3::HandAddress::to_string, "\"service/bus/id\"")
      .def("__repr__", &hand_address_repr)
      .def("__eq__", [](const dh3::HandAddress& a, const dh3::HandAddress& b) { return a == b; })
      .def("__lt__", [](const dh3::HandAddress& a, const dh3::HandAddress& b) { return a < b; })
      .def("__hash__", [](const dh3::HandAddress& a) {
        return py::hash(py::make_tuple(a.service, a.bus, a.can_id));
      });

  m.def(
      "parse_hand_address",
      [](const std::string& text) {
        auto spec = value_or_raise(dh3::parse_hand_spec(text));
        if (!spec.is_full()) {
          raise_error(dh3::Code::invalid_argument,
                      "'" + text + "' is not a full hand address (SERVICE/BUS/ID)");
        }
        return spec.address();
      },
      "text"_a, "The HandAddress of \"service/bus/id\"; dh3.Error(INVALID_ARGUMENT) otherwise.");
}

void bind_reply(py::module_& m) {
  py::class_<dh3::Reply>(m, "Reply",
                         "What a call returns: always a code and, unless OK, a message that says "
                         "why. The other fields matter for some commands only.")
      .def_property_readonly("ok", &dh3::Reply::ok, "True when code is Code.OK.")
      .def("__bool__", &dh3::Reply::ok)
      .def_readonly("code", &dh3::Reply::code)
      .def_readonly("message", &dh3::Reply::message)
      .def_readonly("value", &dh3::Reply::value,
                    "READ: the value read. GRASP: the final position. Writes: the value written.")
      .def_readonly("grasp", &dh3::Reply::grasp,
                    "GRASP: GRASPED (holding something) or MISSED (closed on nothing).")
      .def_readonly("found_ids", &dh3::Reply::found_ids, "SCAN: the CAN IDs that answered.")
      .def_readonly("lease_holder", &dh3::Reply::lease_holder,
                    "Lease commands, and commands refused because of a lease: who holds it.")
      .def("__repr__", [](const dh3::Reply& r) {
        return "Reply(code=" + std::string(dh3::to_string(r.code)) +
               ", value=" + std::to_string(r.value) +
               ", grasp=" + std::string(dh3::to_string(r.grasp)) + ", message='" + r.message + "')";
      });
}

void bind_group_reply(py::module_& m) {
  py::class_<dh3::GroupMemberReply>(m, "GroupMemberReply", "One hand's part of a group command.")
      .def_property_readonly("ok", &dh3::GroupMemberReply::ok)
      .def("__bool__", &dh3::GroupMemberReply::ok)
      .def_readonly("hand", &dh3::GroupMemberReply::hand)
      .def_readonly("code", &dh3::GroupMemberReply::code,
                    "CANCELLED: another hand of the group failed first.")
      .def_readonly("message", &dh3::GroupMemberReply::message)
      .def_readonly("value", &dh3::GroupMemberReply::value, "GRASP: the final position.")
      .def_readonly("grasp", &dh3::GroupMemberReply::grasp)
      .def("__repr__", [](const dh3::GroupMemberReply& r) {
        return "GroupMemberReply(" + r.hand.to_string() +
               ", code=" + std::string(dh3::to_string(r.code)) +
               ", value=" + std::to_string(r.value) +
               ", grasp=" + std::string(dh3::to_string(r.grasp)) + ")";
      });
  py::class_<dh3::GroupReply>(m, "GroupReply",
                              "A group command's one reply: code OK if every hand's is, else "
                              "the first failed hand's; hands in the order given.")
      .def_property_readonly("ok", &dh3::GroupReply::ok)
      .def("__bool__", &dh3::GroupReply::ok)
      .def_readonly("code", &dh3::GroupReply::code)
      .def_readonly("message", &dh3::GroupReply::message,
                    "Every failed hand and why, for every code but OK.")
      .def_readonly("hands", &dh3::GroupReply::hands)
      .def("__repr__", [](const dh3::GroupReply& r) {
        return "GroupReply(code=" + std::string(dh3::to_string(r.code)) +
               ", hands=" + std::to_string(r.hands.size()) + ", message='" + r.message + "')";
      });
}

/// A status value the hand has not reported yet is None in Python, never the
/// -1 that holds its place in C++ (dh3ctl shows "-", JSON null).
template <std::int32_t dh3::HandStatus::*field>
std::optional<std::int32_t> read_or_none(const dh3::HandStatus& s) {
  const std::int32_t value = s.*field;
  return value < 0 ? std::nullopt : std::optional<std::int32_t>(value);
}

std::string status_repr(const dh3::HandStatus& s) {
  const auto position = read_or_none<&dh3::HandStatus::position>(s);
  return "HandStatus(" + s.address.to_string() + ", online=" + (s.online ? "True" : "False") +
         ", initialized=" + (s.initialized ? "True" : "False") +
         ", grip=" + std::string(dh3::to_string(s.grip)) +
         ", position=" + (position ? std::to_string(*position) : std::string("None")) + ")";
}

void bind_hand_status(py::module_& m) {
  using S = dh3::HandStatus;
  py::class_<S>(m, "HandStatus", "The latest status the service published for a hand.")
      .def_readonly("address", &S::address)
      .def_readonly("name", &S::name, "From the service's config, may be empty.")
      .def_readonly("online", &S::online)
      .def_readonly("initialized", &S::initialized)
      .def_readonly("grip", &S::grip)
      .def_property_readonly("position", &read_or_none<&S::position>, "None until read.")
      .def_property_readonly("target_position", &read_or_none<&S::target_position>,
                             "None until written.")
      .def_property_readonly("closing_force", &read_or_none<&S::closing_force>, "None until read.")
      .def_property_readonly("opening_force", &read_or_none<&S::opening_force>, "None until read.")
      .def_property_readonly("rotation", &read_or_none<&S::rotation>, "None until read.")
      .def_property_readonly("rotation_target", &read_or_none<&S::rotation_target>,
                             "None until written.")
      .def_readonly("rotation_state", &S::rotation_state)
      .def_readonly("firmware_version", &S::firmware_version, "Raw 0x1301 value.")
      .def_readonly("firmware_version_text", &S::firmware_version_text)
      .def_readonly("last_error", &S::last_error)
      .def_readonly("last_error_message", &S::last_error_message)
      .def_readonly("lease_holder", &S::lease_holder, "Empty when nobody holds a lease.")
      .def_readonly("timestamp_ns", &S::timestamp_ns,
                    "The service's wall clock, ns since the epoch.")
      .def_readonly("update_seq", &S::update_seq, "Increments on every change of this hand.")
      .def_readonly("read_at_ns", &S::read_at_ns,
                    "When the hand last answered a read whose values are in this sample, on the "
                    "service's wall clock (ns since the epoch); 0 before the hand ever answered.")
      .def_readonly("service_lost", &S::service_lost,
                    "True when the client marked the hand offline itself because its service "
                    "left the domain without saying so.")
      .def("__repr__", &status_repr);
}

void bind_hand_event(py::module_& m) {
  py::class_<dh3::HandEvent>(m, "HandEvent", "Something that happened to a hand.")
      .def_readonly("hand", &dh3::HandEvent::hand)
      .def_readonly("name", &dh3::HandEvent::name)
      .def_readonly("kind", &dh3::HandEvent::kind)
      .def_readonly("position", &dh3::HandEvent::position,
                    "ARRIVED, GRASPED, MISSED: where the fingers stopped; the rotation events: "
                    "where the rotation stopped; None when not read yet as the event went out "
                    "(the status that follows says it). DROPPED: where the fingers held.")
      .def_readonly("target", &dh3::HandEvent::target,
                    "Target in force; after a stop, the target of the motion it ended.")
      .def_readonly("value", &dh3::HandEvent::value,
                    "GRASPED: the closing force; ARRIVED, MISSED, the rotation events, DROPPED, "
                    "FAULT: the status value read; ONLINE: the raw firmware version; OFFLINE: "
                    "unanswered requests in a row.")
      .def_readonly("message", &dh3::HandEvent::message)
      .def_readonly("timestamp_ns", &dh3::HandEvent::timestamp_ns)
      .def_readonly("event_seq", &dh3::HandEvent::event_seq,
                    "Per service; 0 for events the client made itself.")
      .def_readonly("from_client", &dh3::HandEvent::from_client,
                    "True for the events the client makes itself: OFFLINE when a service "
                    "disappears, ONLINE when it is back.")
      .def_property_readonly(
          "named_value",
          [](const dh3::HandEvent& e) -> std::optional<std::pair<std::string, std::int32_t>> {
            const auto named = dh3::named_value(e);
            if (!named) return std::nullopt;
            return std::make_pair(std::string(named->name), named->value);
          },
          "What value means, named: ('closing_force', 40) for GRASPED, ('grip_status', N) for "
          "ARRIVED, MISSED, DROPPED, ('rotation_status', N) for the rotation events, "
          "('firmware_version', raw) for ONLINE, ('unanswered_requests', N) for OFFLINE; None "
          "where it says nothing the kind and the message do not.")
      .def("__repr__", [](const dh3::HandEvent& e) {
        return "HandEvent(" + e.hand.to_string() + ", " + std::string(dh3::to_string(e.kind)) +
               ", position=" + (e.position ? std::to_string(*e.position) : std::string("None")) +
               ")";
      });
}

void bind_service_info(py::module_& m) {
  py::class_<dh3::HandInfo>(m, "HandInfo")
      .def_readonly("can_id", &dh3::HandInfo::can_id)
      .def_readonly("name", &dh3::HandInfo::name);
  py::class_<dh3::BusInfo>(m, "BusInfo")
      .def_readonly("name", &dh3::BusInfo::name)
      .def_readonly("spec", &dh3::BusInfo::spec, "E.g. \"tcp:127.0.0.1:9000\", \"sim:1,2,3\".")
      .def_readonly("link_up", &dh3::BusInfo::link_up)
      .def_readonly("hands", &dh3::BusInfo::hands);
  py::class_<dh3::CommandTraffic>(m, "CommandTraffic",
                                  "What reached this client over DDS for its commands.")
      .def_readonly("requests_written", &dh3::CommandTraffic::requests_written)
      .def_readonly("own_replies", &dh3::CommandTraffic::own_replies,
                    "Replies carrying this client's id.")
      .def_readonly("foreign_replies", &dh3::CommandTraffic::foreign_replies,
                    "Replies to other clients that reached this client and were dropped.");
  py::class_<dh3::WatchTraffic>(m, "WatchTraffic",
                                "What reached this client of the statuses, events and service "
                                "info.")
      .def_readonly("statuses", &dh3::WatchTraffic::statuses)
      .def_readonly("events", &dh3::WatchTraffic::events)
      .def_readonly("infos", &dh3::WatchTraffic::infos)
      .def_readonly("dropped_on_arrival", &dh3::WatchTraffic::dropped_on_arrival,
                    "Samples of cells it does not follow that reached it and were dropped.");
  py::class_<dh3::ServiceInfo>(m, "ServiceInfo")
      .def_readonly("name", &dh3::ServiceInfo::name)
      .def_readonly("version", &dh3::ServiceInfo::version)
      .def_readonly("host", &dh3::ServiceInfo::host)
      .def_readonly("admin_allowed", &dh3::ServiceInfo::admin_allowed)
      .def_readonly("buses", &dh3::ServiceInfo::buses)
      .def_readonly("started_ns", &dh3::ServiceInfo::started_ns)
      .def_readonly("ready", &dh3::ServiceInfo::ready,
                    "The service is on the domain now and calls to it go out at once.");
}

void bind_subscription(py::module_& m) {
  py::class_<PySubscription>(m, "Subscription",
                             "Keeps a callback registered; unsubscribes when unsubscribe() is "
                             "called, when used as a context manager and the block ends, or when "
                             "garbage collected. After unsubscribe() returns the callback is not "
                             "running and will not run again (it may be called from inside the "
                             "callback itself).")
      .def("unsubscribe", &PySubscription::unsubscribe)
      .def("active", &PySubscription::active)
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](PySubscription& s, const py::args&) { s.unsubscribe(); });
}

}  // namespace

void bind_values(py::module_& m) {
  bind_hand_address(m);
  bind_reply(m);
  bind_group_reply(m);
  bind_hand_status(m);
  bind_hand_event(m);
  bind_service_info(m);
  bind_subscription(m);
}

}  // namespace dh3::python
