// dh3.Client.

#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "calls.hpp"
#include "py_client.hpp"
#include "support.hpp"

namespace dh3::python {

namespace {

using namespace pybind11::literals;

std::unique_ptr<PyClient> make_client(int domain, std::string participant_name,
                                      std::string xml_profile_file, std::string xml_profile,
                                      std::vector<std::string> interfaces, bool udp_only,
                                      bool shared_memory,
                                      std::vector<std::string> discovery_servers,
                                      std::string security_dir, std::string security_identity,
                                      double default_timeout, std::string follow) {
  dh3::ClientOptions options;
  options.domain = domain;
  options.participant_name = std::move(participant_name);
  options.xml_profile_file = std::move(xml_profile_file);
  options.xml_profile = std::move(xml_profile);
  options.interfaces = std::move(interfaces);
  options.udp_only = udp_only;
  options.shared_memory = shared_memory;
  options.discovery_servers = std::move(discovery_servers);
  options.security_dir = std::move(security_dir);
  options.security_identity = std::move(security_identity);
  options.default_timeout = to_milliseconds(default_timeout, "default_timeout");
  options.follow = std::move(follow);
  return std::make_unique<PyClient>(std::move(options));
}

/// A const Client method as Python calls it: on the open client (else
/// dh3.Error(NOT_CONNECTED)), with the GIL released.
template <typename R, typename... Args>
auto without_gil(R (dh3::Client::*method)(Args...) const) {
  return [method](PyClient& c, Args... args) {
    auto client = c.client();
    py::gil_scoped_release released;
    return ((*client).*method)(args...);
  };
}

/// Client::subscribe or subscribe_status with a Python callback taking `Arg`;
/// `what` names the callback in reports of what it raised.
template <typename Arg, typename Callback>
auto python_subscribe(dh3::Subscription (dh3::Client::*method)(Callback,
                                                               std::optional<dh3::HandAddress>),
                      const char* what) {
  return [method, what](PyClient& c, py::function callback, std::optional<dh3::HandAddress> only) {
    auto client = c.client();
    auto cb = python_callback<Arg>(std::move(callback), what);
    py::gil_scoped_release released;
    return std::make_unique<PySubscription>(((*client).*method)(std::move(cb), only));
  };
}

void def_life_cycle(py::class_<PyClient>& cls) {
  cls.def(py::init(&make_client), py::kw_only(), "domain"_a = 0,
          "participant_name"_a = "dh3-client", "xml_profile_file"_a = "", "xml_profile"_a = "",
          "interfaces"_a = std::vector<std::string>{}, "udp_only"_a = false,
          "shared_memory"_a = false, "discovery_servers"_a = std::vector<std::string>{},
          "security_dir"_a = "", "security_identity"_a = "operator", "default_timeout"_a = 10.0,
          "follow"_a = "",
          "Joins the DDS domain. domain: 0-232. interfaces: IPv4 addresses of network "
          "interfaces (empty: loopback only; [\"*\"]: all). udp_only: UDP only (the default). "
          "shared_memory: also Fast DDS's shared-memory transport (needs Fast DDS 2.12.1 or "
          "later). discovery_servers: \"HOST[:PORT]\" each. xml_profile_file/xml_profile: a "
          "Fast DDS XML profile (replaces interfaces, udp_only and shared_memory). security_dir/"
          "security_identity: DDS Security credentials. default_timeout: seconds for calls "
          "given no timeout. follow: \"SERVICE\" or \"SERVICE/BUS\": only that cell's "
          "statuses, events and service info are sent to this client (the services filter "
          "them); malformed, the client is not connected and error() says why.")
      .def("close", &PyClient::close,
           "Leaves the domain: pending calls end NOT_CONNECTED, callbacks stop; the client's "
           "Hands answer NOT_CONNECTED from now on.")
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](PyClient& c, const py::args&) { c.close(); })
      .def(
          "connected",
          [](PyClient& c) {
            auto client = c.current();
            if (!client) return false;
            py::gil_scoped_release released;
            return client->connected();
          },
          "False if the DDS participant could not be created (error() says why) or the client "
          "is closed.")
      .def("error", [](PyClient& c) {
        auto client = c.current();
        if (!client) return std::string("the client is closed");
        py::gil_scoped_release released;
        return client->error();
      });
}

void def_queries(py::class_<PyClient>& cls) {
  cls.def("read_only", without_gil(&dh3::Client::read_only),
          "True when DDS Security refused this client commands: every command ends DENIED.")
      .def("client_id", without_gil(&dh3::Client::client_id))
      .def("command_traffic", without_gil(&dh3::Client::command_traffic),
           "What reached this client over DDS for its commands, since it was created.")
      .def("watch_traffic", without_gil(&dh3::Client::watch_traffic),
           "What reached this client of the statuses, events and service info, since it was "
           "created.")
      .def("domain", [](PyClient& c) { return c.client()->domain(); })
      .def(
          "default_timeout",
          [](PyClient& c) {
            return std::chrono::duration<double>(c.client()->default_timeout()).count();
          },
          "Seconds.")
      .def("services", without_gil(&dh3::Client::services),
           "Every service seen on the domain (ready says which are here now).")
      .def("service", without_gil(&dh3::Client::service), "name"_a)
      .def("hands", without_gil(&dh3::Client::hands), "The latest status of every hand seen.")
      .def("status", without_gil(&dh3::Client::status), "address"_a);
}

void def_waits(py::class_<PyClient>& cls) {
  const auto timeout_arg = "timeout"_a = py::none();
  cls.def(
         "wait_for_service",
         [](PyClient& c, const std::string& name, OptionalSeconds t) {
           return value_or_raise(
               c.wait_in_slices<dh3::ServiceInfo>(t, [&](dh3::Client& client, Milliseconds slice) {
                 return client.wait_for_service(name, slice);
               }));
         },
         "name"_a = "", timeout_arg,
         "Waits until the named service (empty: any) is ready; raises dh3.Error(NO_SERVICE) "
         "on timeout.")
      .def("wait_for_statuses", &PyClient::wait_for_statuses, timeout_arg,
           "Waits until every ready service's hands have a status here; True if so in time.")
      .def(
          "hand",
          [](PyClient& c, const dh3::HandAddress& address) {
            return c.wrap(c.client()->hand(address));
          },
          "address"_a, "A hand by address; no lookup, no waiting.")
      .def("find_hand", &PyClient::find_hand, "spec"_a,
           "A hand by \"SERVICE/BUS/ID\", \"BUS/ID\", \"ID\" or name among the hands known now; "
           "raises dh3.Error otherwise.")
      .def(
          "wait_for_hand",
          [](PyClient& c, const std::string& spec, OptionalSeconds t) {
            return c.wrap(value_or_raise(
                c.wait_in_slices<dh3::Hand>(t, [&](dh3::Client& client, Milliseconds slice) {
                  return client.wait_for_hand(spec, slice);
                })));
          },
          "spec"_a, timeout_arg,
          "Waits until spec names exactly one hand whose status this client has. Raises "
          "dh3.Error: NO_SERVICE if its service never appeared, UNKNOWN_HAND if the service is "
          "here but has no such hand, INVALID_ARGUMENT for bad or ambiguous specs.");
}

void def_calls(py::class_<PyClient>& cls) {
  const auto timeout_arg = "timeout"_a = py::none();
  cls.def(
         "scan",
         [](PyClient& c, const std::string& service, const std::string& bus, OptionalSeconds t) {
           auto client = c.client();
           auto future =
               start_call([&] { return client->scan_async(service, bus, to_timeout(t)); });
           client.reset();  // close() while this waits ends the call NOT_CONNECTED
           return wait_interruptibly(future);
         },
         "service"_a, "bus"_a, timeout_arg,
         "Probes a bus for hands now; reply.found_ids lists those that answered.")
      .def(
          "scan_async",
          [](PyClient& c, const std::string& service, const std::string& bus, OptionalSeconds t) {
            auto client = c.client();
            return async_call<dh3::Reply>([&](dh3::ReplyCallback done) {
              client->scan_async(service, bus, std::move(done), to_timeout(t));
            });
          },
          "service"_a, "bus"_a, timeout_arg)
      .def(
          "group",
          [](PyClient& c, dh3::GroupCommand command, std::vector<dh3::HandAddress> hands,
             std::int32_t value, OptionalSeconds t) {
            auto client = c.client();
            std::future<dh3::GroupReply> future;
            {
              py::gil_scoped_release released;
              future = client->group_async(command, std::move(hands), value, to_timeout(t));
            }
            client.reset();  // close() while this waits ends the call NOT_CONNECTED
            return wait_interruptibly(future);
          },
          "command"_a, "hands"_a, "value"_a = 0, timeout_arg,
          "One command to several hands of one service, together and all or none: if any hand "
          "fails its check (offline, not initialized, leased by another client, value out of "
          "range) nothing is sent and each failing hand says why. Returns one GroupReply once "
          "every hand's command ended.")
      .def(
          "group_async",
          [](PyClient& c, dh3::GroupCommand command, std::vector<dh3::HandAddress> hands,
             std::int32_t value, OptionalSeconds t) {
            auto client = c.client();
            return async_call<dh3::GroupReply>([&](dh3::GroupReplyCallback done) {
              client->group_async(command, std::move(hands), value, std::move(done), to_timeout(t));
            });
          },
          "command"_a, "hands"_a, "value"_a = 0, timeout_arg,
          "group() without waiting: a concurrent.futures.Future of the GroupReply.")
      .def("subscribe",
           python_subscribe<dh3::HandEvent>(&dh3::Client::subscribe, "dh3: event callback"),
           "callback"_a, "only"_a = py::none(),
           "Calls callback(event) for every event of every hand (or of only) from now on, on the "
           "client's thread. Keep the returned Subscription.")
      .def(
          "subscribe_status",
          python_subscribe<dh3::HandStatus>(&dh3::Client::subscribe_status, "dh3: status callback"),
          "callback"_a, "only"_a = py::none(),
          "Calls callback(status) for every new status sample (the ones already received "
          "first) of every hand or of only. Keep the returned Subscription.");
}

}  // namespace

void bind_client(py::module_& m) {
  py::class_<PyClient> cls(m, "Client",
                           "Finds DH-3 hands on a DDS domain and drives them. Never raises on "
                           "creation: check connected() and error(). A Client and its Hands may "
                           "be used from any number of threads at once.");
  def_life_cycle(cls);
  def_queries(cls);
  def_waits(cls);
  def_calls(cls);
}

}  // namespace dh3::python
