// dh3.Hand. Every command is bound twice from its C++ Hand::NAME_async: NAME,
// which waits and returns a Reply, and NAME_async, which returns a
// concurrent.futures.Future of a Reply.

#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <tuple>
#include <utility>

#include "bindings.hpp"
#include "calls.hpp"
#include "py_hand.hpp"
#include "support.hpp"

namespace dh3::python {

namespace {

using namespace pybind11::literals;

/// How a command's parameter is given in Python: as in C++, but for a
/// duration (a lease's ttl), which is seconds.
template <typename T>
struct FromPython {
  using type = T;
  static T convert(T value) { return value; }
};
template <>
struct FromPython<std::chrono::milliseconds> {
  using type = double;
  static Milliseconds convert(double seconds) { return to_milliseconds(seconds, "ttl"); }
};

/// A Hand command in C++, as its std::future form: its parameters, the last
/// of which is the timeout.
template <typename... Params>
using HandCommand = std::future<dh3::Reply> (dh3::Hand::*)(Params...);

/// The same command's completion-callback form (Params' last is the timeout).
template <typename Before, typename... Params>
struct CallbackFormOf;
template <std::size_t... I, typename... Params>
struct CallbackFormOf<std::index_sequence<I...>, Params...> {
  using type = void (dh3::Hand::*)(std::tuple_element_t<I, std::tuple<Params...>>...,
                                   dh3::ReplyCallback, dh3::Timeout);
};
template <typename... Params>
using CallbackForm =
    typename CallbackFormOf<std::make_index_sequence<sizeof...(Params) - 1>, Params...>::type;

/// The Python function of a command: (hand, its parameters but the timeout,
/// timeout in seconds or None). Parameters are converted before the call
/// starts, the timeout as it starts. The blocking one waits for the std::future
/// form (fulfilled where the call ends, so it may run in a callback); the
/// asynchronous one returns a Future that the callback form completes.
template <bool kBlocking, typename... Params, std::size_t... I>
auto python_command(HandCommand<Params...> future_form, CallbackForm<Params...> callback_form,
                    std::index_sequence<I...> /*before_timeout*/) {
  using All = std::tuple<Params...>;
  return [future_form, callback_form](
             PyHand& h, typename FromPython<std::tuple_element_t<I, All>>::type... args,
             OptionalSeconds t) {
    std::tuple<std::tuple_element_t<I, All>...> converted{
        FromPython<std::tuple_element_t<I, All>>::convert(args)...};
    if constexpr (kBlocking) {
      return blocking_call([&] {
        return std::apply(
            [&](auto&... values) { return (h.hand().*future_form)(values..., to_timeout(t)); },
            converted);
      });
    } else {
      return async_call<dh3::Reply>([&](dh3::ReplyCallback done) {
        std::apply(
            [&](auto&... values) {
              (h.hand().*callback_form)(values..., std::move(done), to_timeout(t));
            },
            converted);
      });
    }
  };
}

/// Binds NAME (with `doc`) and NAME_async from the two overloads of
/// Hand::NAME_async (given twice: the std::future one and the callback one
/// are picked by type); `params` name the parameters before the timeout.
template <typename... Params, typename... Names>
void def_command(py::class_<PyHand>& hand, const std::string& name,
                 HandCommand<Params...> future_form, CallbackForm<Params...> callback_form,
                 const char* doc, const Names&... params) {
  constexpr auto before_timeout = std::make_index_sequence<sizeof...(Params) - 1>{};
  hand.def(name.c_str(), python_command<true>(future_form, callback_form, before_timeout),
           params..., "timeout"_a = py::none(), doc);
  hand.def((name + "_async").c_str(),
           python_command<false>(future_form, callback_form, before_timeout), params...,
           "timeout"_a = py::none());
}

void def_motion_commands(py::class_<PyHand>& hand) {
  using H = dh3::Hand;
  def_command(hand, "initialize", &H::initialize_async, &H::initialize_async,
              "Initializes the hand; the reply comes once initialization finished.");
  def_command(hand, "move_to", &H::move_to_async, &H::move_to_async,
              "Moves the fingers to position percent (0 closed - 100 open).", "position"_a);
  def_command(hand, "rotate_to", &H::rotate_to_async, &H::rotate_to_async,
              "Rotates to percent of 90 degrees.", "percent"_a);
  def_command(hand, "set_force", &H::set_force_async, &H::set_force_async,
              "Sets the closing (gripping) force and, when given, the opening force, in percent "
              "(20-100). With both, the first failure is the reply.",
              "closing"_a, "opening"_a = py::none());
  def_command(hand, "grasp", &H::grasp_async, &H::grasp_async,
              "Closes with force percent: reply.grasp is GRASPED (stopped on an object) or MISSED "
              "(closed on nothing); reply.value the final position.",
              "force"_a);
  def_command(hand, "release", &H::release_async, &H::release_async,
              "Opens to position; the reply comes once arrived.", "position"_a);
  def_command(hand, "stop", &H::stop_async, &H::stop_async,
              "Holds the current position; pending motion ends CANCELLED.");
}

void def_register_and_bus_commands(py::class_<PyHand>& hand) {
  using H = dh3::Hand;
  def_command(hand, "read", &H::read_async, &H::read_async,
              "Reads a register (dh3.reg.position, ...); reply.value is what was read.",
              "register_code"_a);
  def_command(hand, "set_can_id", &H::set_can_id_async, &H::set_can_id_async,
              "Administrative (the service must allow it; the hand needs a reboot after).",
              "can_id"_a);
  def_command(hand, "set_baud_rate", &H::set_baud_rate_async, &H::set_baud_rate_async,
              "Administrative: baud rate index 0 (500 kbps) - 5 (100 kbps).", "index"_a);
  def_command(hand, "scan_bus", &H::scan_bus_async, &H::scan_bus_async,
              "Probes this hand's whole bus for hands now; reply.found_ids lists them.");
}

void def_lease_commands(py::class_<PyHand>& hand) {
  using H = dh3::Hand;
  def_command(hand, "acquire_lease", &H::acquire_lease_async, &H::acquire_lease_async,
              "Leases: while this client holds one (ttl seconds), other clients' motion and write "
              "commands to the hand are DENIED. A lease ends on release, on expiry, or when this "
              "client leaves the domain.",
              "ttl"_a);
  def_command(hand, "renew_lease", &H::renew_lease_async, &H::renew_lease_async, nullptr, "ttl"_a);
  def_command(hand, "release_lease", &H::release_lease_async, &H::release_lease_async, nullptr);
}

}  // namespace

void bind_hand(py::module_& m) {
  py::class_<PyHand> hand(
      m, "Hand",
      "A handle on one hand; every copy drives the same hand through the same "
      "client. Every command has a blocking form, which returns a Reply, and an "
      "asynchronous one (NAME_async), which returns a concurrent.futures.Future of "
      "a Reply. Each has a timeout in seconds (None: the client's default_timeout) "
      "and always ends: with the service's reply or with the client's own code "
      "(NO_SERVICE, NO_REPLY, SERVICE_LOST, NOT_CONNECTED). Nothing raises but "
      "KeyboardInterrupt (Ctrl-C ends the wait of a blocking call).");
  hand.def_property_readonly("address", [](PyHand& h) { return h.hand().address(); })
      .def("status", &PyHand::status, "The latest status, None until the service published one.")
      .def("online",
           [](PyHand& h) {
             py::gil_scoped_release released;
             return h.hand().online();
           })
      .def("wait_until", &PyHand::wait_until, "predicate"_a, "timeout"_a = py::none(),
           "Waits until predicate(status) is true (checked at once, then on every new status); "
           "returns that status, None on timeout.");
  def_motion_commands(hand);
  def_register_and_bus_commands(hand);
  def_lease_commands(hand);
  hand.def(
          "subscribe",
          [](PyHand& h, py::function callback) {
            auto cb = python_callback<dh3::HandEvent>(std::move(callback), "dh3: event callback");
            py::gil_scoped_release released;
            return std::make_unique<PySubscription>(h.hand().subscribe(std::move(cb)));
          },
          "callback"_a,
          "Calls callback(event) for each event of this hand from now on, on the client's "
          "thread (with the GIL). Keep the returned Subscription: the callback ends with it.")
      .def("__repr__", [](PyHand& h) { return "Hand(" + h.hand().address().to_string() + ")"; });
}

}  // namespace dh3::python
