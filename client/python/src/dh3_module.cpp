// dh3._dh3: the Python binding of libdh3client (issue 16). The package dh3
// (dh3/__init__.py) re-exports these names and defines the enums as Python
// enum.IntEnum classes and the exception dh3.Error; this file converts to and
// from them at the boundary.
//
// Threads and the GIL:
// - Every call into the client runs with the GIL released: the client's own
//   thread takes the GIL to run Python callbacks, and it may do so while a
//   client lock is held, so holding the GIL while waiting for a client lock
//   could deadlock.
// - Blocking calls wait in short slices and check for signals (Ctrl-C) with the
//   GIL held between them, so a KeyboardInterrupt ends the wait promptly; the
//   abandoned call still ends on its own within its timeout.
// - Python callbacks and predicates are only ever run with the GIL held, and
//   never while a client lock is held.
// - Python objects kept by C++ (callbacks, futures) are released with the GIL.

#include <Python.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "dh3/address.hpp"
#include "dh3/client.hpp"
#include "dh3/registers.hpp"
#include "dh3/types.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

namespace {

using Milliseconds = std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;

/// How long a blocking call waits with the GIL released before it checks for
/// signals: short enough that Ctrl-C feels immediate.
constexpr Milliseconds kSlice{50};

// ---------------------------------------------------------------------------
// Enums: dh3.Code & co. are enum.IntEnum classes defined in dh3/__init__.py;
// the casters below turn the C++ enums into members of those classes and
// accept any int (an IntEnum member is one) coming back.

py::object python_enum_class(const char* name) {
  return py::module_::import("dh3").attr(name);
}

}  // namespace

#define DH3_PYTHON_ENUM_CASTER(CppType, PyName)                                             \
  namespace pybind11::detail {                                                              \
  template <>                                                                               \
  struct type_caster<CppType> {                                                             \
    PYBIND11_TYPE_CASTER(CppType, const_name(PyName));                                      \
    bool load(handle source, bool /*convert*/) {                                            \
      if (!source || !PyLong_Check(source.ptr())) return false;                             \
      const long number = PyLong_AsLong(source.ptr());                                      \
      if (number == -1 && PyErr_Occurred()) {                                               \
        PyErr_Clear();                                                                      \
        return false;                                                                       \
      }                                                                                     \
      value = static_cast<CppType>(number);                                                 \
      return true;                                                                          \
    }                                                                                       \
    static handle cast(CppType source, return_value_policy /*policy*/, handle /*parent*/) { \
      return python_enum_class(PyName)(static_cast<int>(source)).release();                 \
    }                                                                                       \
  };                                                                                        \
  }

DH3_PYTHON_ENUM_CASTER(dh3::Code, "Code")
DH3_PYTHON_ENUM_CASTER(dh3::GraspOutcome, "GraspOutcome")
DH3_PYTHON_ENUM_CASTER(dh3::GripState, "GripState")
DH3_PYTHON_ENUM_CASTER(dh3::RotationState, "RotationState")
DH3_PYTHON_ENUM_CASTER(dh3::EventKind, "EventKind")

namespace {

// ---------------------------------------------------------------------------
// Timeouts: seconds as float in Python; None = the client's default.

using OptionalSeconds = std::optional<double>;

Milliseconds to_milliseconds(double seconds, const char* what) {
  if (!std::isfinite(seconds) || seconds < 0.0) {
    throw py::value_error(std::string(what) + " must be a finite number of seconds >= 0");
  }
  // Rounded up, at least 1 ms: zero means "the default" to the C++ API.
  const auto ms = static_cast<long long>(std::ceil(seconds * 1000.0));
  return Milliseconds(std::max(ms, 1LL));
}

dh3::Timeout to_timeout(const OptionalSeconds& seconds) {
  if (!seconds) return dh3::Timeout::zero();
  return to_milliseconds(*seconds, "timeout");
}

/// Raises dh3.Error(code, message).
[[noreturn]] void raise_error(dh3::Code code, const std::string& message) {
  py::object error = python_enum_class("Error")(py::cast(code), message);
  PyErr_SetObject(error.get_type().ptr(), error.ptr());
  throw py::error_already_set();
}

/// Raises the pending Python exception (KeyboardInterrupt, ...) if a signal
/// handler raised one. The GIL must be held.
void check_signals() {
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

/// Waits for `future` in slices, releasing the GIL while waiting.
template <typename T>
T wait_interruptibly(std::future<T>& future) {
  for (;;) {
    bool ready = false;
    {
      py::gil_scoped_release released;
      ready = future.wait_for(kSlice) == std::future_status::ready;
    }
    if (ready) return future.get();
    check_signals();
  }
}

// ---------------------------------------------------------------------------
// Python objects owned by C++: released with the GIL held (or leaked if the
// interpreter is already gone, which is harmless at exit).

struct PyObjectDeleter {
  void operator()(py::object* object) const {
    if (!Py_IsInitialized()) return;
    py::gil_scoped_acquire gil;
    delete object;
  }
};
using SharedPyObject = std::shared_ptr<py::object>;

SharedPyObject share(py::object object) {
  return SharedPyObject(new py::object(std::move(object)), PyObjectDeleter{});
}

// ---------------------------------------------------------------------------
// Asynchronous calls: a concurrent.futures.Future completed by a thread that
// waits for the C++ future. Threads in flight are counted so that interpreter
// exit (dh3's atexit hook) can wait for them after closing the clients.

std::mutex g_in_flight_mutex;
std::condition_variable g_in_flight_done;
int g_in_flight = 0;

py::object to_python_future(std::future<dh3::Reply> reply) {
  py::object future = py::module_::import("concurrent.futures").attr("Future")();
  future.attr("set_running_or_notify_cancel")();
  auto target = share(future);
  {
    std::lock_guard lock(g_in_flight_mutex);
    ++g_in_flight;
  }
  std::thread([reply = std::move(reply), target = std::move(target)]() mutable {
    dh3::Reply result = reply.get();
    if (Py_IsInitialized()) {
      py::gil_scoped_acquire gil;
      try {
        target->attr("set_result")(py::cast(std::move(result)));
      } catch (py::error_already_set& error) {
        error.discard_as_unraisable("dh3: completing a Future");
      }
      target.reset();
    }
    std::lock_guard lock(g_in_flight_mutex);
    --g_in_flight;
    g_in_flight_done.notify_all();
  }).detach();
  return future;
}

/// Starts a call with the GIL released.
template <typename Start>
std::future<dh3::Reply> start_call(Start&& start) {
  py::gil_scoped_release released;
  return start();
}

template <typename Start>
dh3::Reply blocking_call(Start&& start) {
  auto future = start_call(std::forward<Start>(start));
  return wait_interruptibly(future);
}

template <typename Start>
py::object async_call(Start&& start) {
  return to_python_future(start_call(std::forward<Start>(start)));
}

// ---------------------------------------------------------------------------
// Callbacks from the client's thread into Python.

template <typename Arg>
std::function<void(const Arg&)> python_callback(py::function callback, const char* what) {
  auto target = share(std::move(callback));
  return [target, what](const Arg& argument) {
    if (!Py_IsInitialized()) return;
    py::gil_scoped_acquire gil;
    try {
      (*target)(argument);
    } catch (py::error_already_set& error) {
      // The client's thread has nobody to raise to: report like Python does
      // for exceptions in __del__ and carry on with the next callback.
      error.discard_as_unraisable(what);
    }
  };
}

/// A Subscription whose unsubscribe (which waits for a running callback to
/// end) releases the GIL: the callback may be waiting for it.
class PySubscription {
 public:
  explicit PySubscription(dh3::Subscription subscription)
      : subscription_(std::move(subscription)) {}
  ~PySubscription() { unsubscribe(); }
  PySubscription(const PySubscription&) = delete;
  PySubscription& operator=(const PySubscription&) = delete;

  void unsubscribe() {
    if (!Py_IsInitialized() || !PyGILState_Check()) {
      subscription_.unsubscribe();
      return;
    }
    py::gil_scoped_release released;
    subscription_.unsubscribe();
  }
  [[nodiscard]] bool active() const { return subscription_.active(); }

 private:
  dh3::Subscription subscription_;
};

// ---------------------------------------------------------------------------
// Hand and Client wrappers: they add what waiting in slices needs (the
// client's default timeout) and release the GIL around every call.

class PyHand {
 public:
  PyHand(dh3::Hand hand, Milliseconds default_timeout)
      : hand_(std::move(hand)), default_timeout_(default_timeout) {}

  dh3::Hand& hand() { return hand_; }
  [[nodiscard]] Milliseconds effective(const OptionalSeconds& timeout) const {
    return timeout ? to_milliseconds(*timeout, "timeout") : default_timeout_;
  }

  std::optional<dh3::HandStatus> status() const {
    py::gil_scoped_release released;
    return hand_.status();
  }

  /// Waits until `predicate(status)` is true. The C++ wait only tells that a
  /// new status arrived (no Python runs under the client's lock); the
  /// predicate runs here, with the GIL held.
  std::optional<dh3::HandStatus> wait_until(const py::function& predicate,
                                            const OptionalSeconds& timeout) const {
    const auto deadline = Clock::now() + effective(timeout);
    std::optional<dh3::HandStatus> seen = status();
    for (;;) {
      if (seen && py::cast<bool>(predicate(*seen))) return seen;
      std::optional<dh3::HandStatus> next;
      for (;;) {
        const auto left = std::chrono::duration_cast<Milliseconds>(deadline - Clock::now());
        if (left <= Milliseconds::zero()) return std::nullopt;
        {
          py::gil_scoped_release released;
          next = hand_.wait_until(
              [&seen](const dh3::HandStatus& s) { return !seen || is_newer(s, *seen); },
              std::clamp(left, Milliseconds(1), kSlice));
        }
        if (next) break;
        check_signals();
      }
      seen = std::move(next);
    }
  }

 private:
  static bool is_newer(const dh3::HandStatus& s, const dh3::HandStatus& old) {
    return s.update_seq != old.update_seq || s.timestamp_ns != old.timestamp_ns ||
           s.online != old.online || s.service_lost != old.service_lost;
  }

  dh3::Hand hand_;
  Milliseconds default_timeout_;
};

class PyClient;
std::mutex g_clients_mutex;
std::set<PyClient*> g_clients;

/// The C++ client, shared by the calls in progress; destroyed without the GIL
/// (~Client waits for the callback thread, which may be waiting for the GIL).
using ClientPtr = std::shared_ptr<dh3::Client>;

void destroy_client(dh3::Client* client) {
  if (Py_IsInitialized() && PyGILState_Check()) {
    py::gil_scoped_release released;
    delete client;
  } else {
    delete client;
  }
}

class PyClient {
 public:
  explicit PyClient(dh3::ClientOptions options) {
    {
      py::gil_scoped_release released;
      client_ = ClientPtr(new dh3::Client(std::move(options)), &destroy_client);
    }
    std::lock_guard lock(g_clients_mutex);
    g_clients.insert(this);
  }
  ~PyClient() {
    {
      std::lock_guard lock(g_clients_mutex);
      g_clients.erase(this);
    }
    close();
  }
  PyClient(const PyClient&) = delete;
  PyClient& operator=(const PyClient&) = delete;

  /// Leaves the domain: pending calls end NOT_CONNECTED, callbacks stop, and
  /// Hands of this client answer NOT_CONNECTED from now on. (A call another
  /// thread is starting at this moment finishes first.)
  void close() {
    ClientPtr closing;
    {
      std::lock_guard lock(mutex_);
      closing = std::move(client_);
    }
    closing.reset();
  }

  /// The client, or dh3.Error(NOT_CONNECTED) once closed. The GIL must be held.
  ClientPtr client() {
    ClientPtr current;
    {
      std::lock_guard lock(mutex_);
      current = client_;
    }
    if (!current) raise_error(dh3::Code::not_connected, "the client is closed");
    return current;
  }
  /// The client, or null once closed.
  ClientPtr current() {
    std::lock_guard lock(mutex_);
    return client_;
  }

  [[nodiscard]] Milliseconds effective(const OptionalSeconds& timeout) {
    return timeout ? to_milliseconds(*timeout, "timeout") : client()->default_timeout();
  }

  PyHand wrap(dh3::Hand hand) { return PyHand(std::move(hand), client()->default_timeout()); }

  /// Repeats a waiting lookup in slices until it succeeds, fails for good
  /// (INVALID_ARGUMENT) or the deadline passes; the last answer. The client is
  /// taken anew for each slice, so close() ends the wait (NOT_CONNECTED).
  template <typename T, typename Lookup>
  dh3::Found<T> wait_in_slices(const OptionalSeconds& timeout, Lookup&& lookup) {
    const auto whole = effective(timeout);
    const auto deadline = Clock::now() + whole;
    for (;;) {
      const auto left = std::chrono::duration_cast<Milliseconds>(deadline - Clock::now());
      const auto slice = std::clamp(left, Milliseconds(1), kSlice);
      auto current = client();
      std::optional<dh3::Found<T>> found;
      {
        py::gil_scoped_release released;
        found.emplace(lookup(*current, slice));
        current.reset();
      }
      if (*found || found->code() == dh3::Code::invalid_argument) return std::move(*found);
      if (left <= kSlice) {
        // The message names the last slice's wait; the caller waited `whole`.
        return {found->code(), replace_duration(found->message(), slice, whole)};
      }
      check_signals();
    }
  }

 private:
  /// libdh3client's spelling of a duration (conversions.cpp).
  static std::string describe(Milliseconds duration) {
    if (duration.count() < 1000) return std::to_string(duration.count()) + " ms";
    char text[32];
    std::snprintf(text, sizeof text, "%.3g s", static_cast<double>(duration.count()) / 1000.0);
    return text;
  }
  static std::string replace_duration(std::string message, Milliseconds slice, Milliseconds whole) {
    const std::string from = " within " + describe(slice);
    const auto at = message.rfind(from);
    if (at != std::string::npos) message.replace(at, from.size(), " within " + describe(whole));
    return message;
  }

 private:
  std::mutex mutex_;
  ClientPtr client_;
};

/// Closes every client (interpreter exit) and waits for the threads that
/// complete Futures, so none of them runs while Python shuts down.
void shutdown(double seconds) {
  std::vector<PyClient*> clients;
  {
    std::lock_guard lock(g_clients_mutex);
    clients.assign(g_clients.begin(), g_clients.end());
  }
  for (auto* client : clients) client->close();
  py::gil_scoped_release released;
  std::unique_lock lock(g_in_flight_mutex);
  g_in_flight_done.wait_for(lock, to_milliseconds(seconds, "timeout"),
                            [] { return g_in_flight == 0; });
}

template <typename T>
T value_or_raise(dh3::Found<T> found) {
  if (!found) raise_error(found.code(), found.message());
  return std::move(found.value());
}

std::string hand_address_repr(const dh3::HandAddress& a) {
  return "HandAddress(service='" + a.service + "', bus='" + a.bus +
         "', can_id=" + std::to_string(a.can_id) + ")";
}

}  // namespace

PYBIND11_MODULE(_dh3, m) {
  m.doc() = "The compiled part of dh3 (libdh3client); import dh3 instead, which re-exports these.";

  m.def(
      "to_string", [](dh3::Code c) { return std::string(dh3::to_string(c)); }, "code"_a);
  m.def(
      "_to_string",
      [](const std::string& kind, int number) -> std::string {
        if (kind == "Code") return std::string(dh3::to_string(static_cast<dh3::Code>(number)));
        if (kind == "GraspOutcome")
          return std::string(dh3::to_string(static_cast<dh3::GraspOutcome>(number)));
        if (kind == "GripState")
          return std::string(dh3::to_string(static_cast<dh3::GripState>(number)));
        if (kind == "RotationState")
          return std::string(dh3::to_string(static_cast<dh3::RotationState>(number)));
        if (kind == "EventKind")
          return std::string(dh3::to_string(static_cast<dh3::EventKind>(number)));
        throw py::value_error("no enum " + kind);
      },
      "Spells an enum value the way libdh3client does (used to check dh3's enums).");
  m.def("_shutdown", &shutdown, "timeout"_a = 5.0,
        "Closes every client and waits for pending Futures (dh3 calls it at exit).");

  auto reg = m.def_submodule("reg", "Register codes (function << 8 | sub-function).");
  for (const auto& r : dh3::registers()) reg.attr(py::str(std::string(r.name))) = r.code;
  m.def(
      "register_name", [](std::uint16_t code) { return std::string(dh3::register_name(code)); },
      "code"_a, "\"position\" for 0x0602; empty for codes outside the map.");
  m.def("parse_register", &dh3::parse_register, "text"_a,
        "A register by name (\"position\", \"grip-status\") or by code (\"0x0602\", \"1538\"); "
        "None if there is none.");
  m.def("firmware_version_text", &dh3::firmware_version_text, "raw"_a,
        "Firmware version 0x1301 as text: raw 0x04010200 reads \"4.1.2.0\".");

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

  py::class_<dh3::HandStatus>(m, "HandStatus",
                              "The latest status the service published for a hand.")
      .def_readonly("address", &dh3::HandStatus::address)
      .def_readonly("name", &dh3::HandStatus::name, "From the service's config, may be empty.")
      .def_readonly("online", &dh3::HandStatus::online)
      .def_readonly("initialized", &dh3::HandStatus::initialized)
      .def_readonly("grip", &dh3::HandStatus::grip)
      .def_readonly("position", &dh3::HandStatus::position, "-1 until read.")
      .def_readonly("target_position", &dh3::HandStatus::target_position, "-1 until written.")
      .def_readonly("closing_force", &dh3::HandStatus::closing_force)
      .def_readonly("opening_force", &dh3::HandStatus::opening_force)
      .def_readonly("rotation", &dh3::HandStatus::rotation)
      .def_readonly("rotation_target", &dh3::HandStatus::rotation_target)
      .def_readonly("rotation_state", &dh3::HandStatus::rotation_state)
      .def_readonly("firmware_version", &dh3::HandStatus::firmware_version, "Raw 0x1301 value.")
      .def_readonly("firmware_version_text", &dh3::HandStatus::firmware_version_text)
      .def_readonly("last_error", &dh3::HandStatus::last_error)
      .def_readonly("last_error_message", &dh3::HandStatus::last_error_message)
      .def_readonly("lease_holder", &dh3::HandStatus::lease_holder,
                    "Empty when nobody holds a lease.")
      .def_readonly("timestamp_ns", &dh3::HandStatus::timestamp_ns,
                    "The service's wall clock, ns since the epoch.")
      .def_readonly("update_seq", &dh3::HandStatus::update_seq,
                    "Increments on every change of this hand.")
      .def_readonly("service_lost", &dh3::HandStatus::service_lost,
                    "True when the client marked the hand offline itself because its service "
                    "left the domain without saying so.")
      .def("__repr__", [](const dh3::HandStatus& s) {
        return "HandStatus(" + s.address.to_string() + ", online=" + (s.online ? "True" : "False") +
               ", initialized=" + (s.initialized ? "True" : "False") +
               ", grip=" + std::string(dh3::to_string(s.grip)) +
               ", position=" + std::to_string(s.position) + ")";
      });

  py::class_<dh3::HandEvent>(m, "HandEvent", "Something that happened to a hand.")
      .def_readonly("hand", &dh3::HandEvent::hand)
      .def_readonly("name", &dh3::HandEvent::name)
      .def_readonly("kind", &dh3::HandEvent::kind)
      .def_readonly("position", &dh3::HandEvent::position, "Position when it happened.")
      .def_readonly("target", &dh3::HandEvent::target, "Target in force.")
      .def_readonly("value", &dh3::HandEvent::value, "Status value or force that explains it.")
      .def_readonly("message", &dh3::HandEvent::message)
      .def_readonly("timestamp_ns", &dh3::HandEvent::timestamp_ns)
      .def_readonly("event_seq", &dh3::HandEvent::event_seq,
                    "Per service; 0 for events the client made itself.")
      .def_readonly("from_client", &dh3::HandEvent::from_client,
                    "True for the OFFLINE events the client emits when a service disappears.")
      .def("__repr__", [](const dh3::HandEvent& e) {
        return "HandEvent(" + e.hand.to_string() + ", " + std::string(dh3::to_string(e.kind)) +
               ", position=" + std::to_string(e.position) + ")";
      });

  py::class_<dh3::HandInfo>(m, "HandInfo")
      .def_readonly("can_id", &dh3::HandInfo::can_id)
      .def_readonly("name", &dh3::HandInfo::name);
  py::class_<dh3::BusInfo>(m, "BusInfo")
      .def_readonly("name", &dh3::BusInfo::name)
      .def_readonly("spec", &dh3::BusInfo::spec, "E.g. \"tcp:127.0.0.1:9000\", \"sim:1,2,3\".")
      .def_readonly("link_up", &dh3::BusInfo::link_up)
      .def_readonly("hands", &dh3::BusInfo::hands);
  py::class_<dh3::ServiceInfo>(m, "ServiceInfo")
      .def_readonly("name", &dh3::ServiceInfo::name)
      .def_readonly("version", &dh3::ServiceInfo::version)
      .def_readonly("host", &dh3::ServiceInfo::host)
      .def_readonly("admin_allowed", &dh3::ServiceInfo::admin_allowed)
      .def_readonly("buses", &dh3::ServiceInfo::buses)
      .def_readonly("started_ns", &dh3::ServiceInfo::started_ns)
      .def_readonly("ready", &dh3::ServiceInfo::ready,
                    "The service is on the domain now and calls to it go out at once.");

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

  using Seconds = OptionalSeconds;
  const auto timeout_arg = "timeout"_a = py::none();
  py::class_<PyHand>(m, "Hand",
                     "A handle on one hand; every copy drives the same hand through the same "
                     "client. Every command has a blocking form, which returns a Reply, and an "
                     "asynchronous one (NAME_async), which returns a concurrent.futures.Future of "
                     "a Reply. Each has a timeout in seconds (None: the client's default_timeout) "
                     "and always ends: with the service's reply or with the client's own code "
                     "(NO_SERVICE, NO_REPLY, SERVICE_LOST, NOT_CONNECTED). Nothing raises but "
                     "KeyboardInterrupt (Ctrl-C ends the wait of a blocking call).")
      .def_property_readonly("address", [](PyHand& h) { return h.hand().address(); })
      .def("status", &PyHand::status, "The latest status, None until the service published one.")
      .def("online",
           [](PyHand& h) {
             py::gil_scoped_release released;
             return h.hand().online();
           })
      .def("wait_until", &PyHand::wait_until, "predicate"_a, timeout_arg,
           "Waits until predicate(status) is true (checked at once, then on every new status); "
           "returns that status, None on timeout.")
      .def(
          "initialize",
          [](PyHand& h, Seconds t) {
            return blocking_call([&] { return h.hand().initialize_async(to_timeout(t)); });
          },
          timeout_arg, "Initializes the hand; the reply comes once initialization finished.")
      .def(
          "initialize_async",
          [](PyHand& h, Seconds t) {
            return async_call([&] { return h.hand().initialize_async(to_timeout(t)); });
          },
          timeout_arg)
      .def(
          "move_to",
          [](PyHand& h, std::int32_t position, Seconds t) {
            return blocking_call([&] { return h.hand().move_to_async(position, to_timeout(t)); });
          },
          "position"_a, timeout_arg, "Moves the fingers to position percent (0 closed - 100 open).")
      .def(
          "move_to_async",
          [](PyHand& h, std::int32_t position, Seconds t) {
            return async_call([&] { return h.hand().move_to_async(position, to_timeout(t)); });
          },
          "position"_a, timeout_arg)
      .def(
          "rotate_to",
          [](PyHand& h, std::int32_t percent, Seconds t) {
            return blocking_call([&] { return h.hand().rotate_to_async(percent, to_timeout(t)); });
          },
          "percent"_a, timeout_arg, "Rotates to percent of 90 degrees.")
      .def(
          "rotate_to_async",
          [](PyHand& h, std::int32_t percent, Seconds t) {
            return async_call([&] { return h.hand().rotate_to_async(percent, to_timeout(t)); });
          },
          "percent"_a, timeout_arg)
      .def(
          "set_force",
          [](PyHand& h, std::int32_t closing, std::optional<std::int32_t> opening, Seconds t) {
            return blocking_call(
                [&] { return h.hand().set_force_async(closing, opening, to_timeout(t)); });
          },
          "closing"_a, "opening"_a = py::none(), timeout_arg,
          "Sets the closing (gripping) force and, when given, the opening force, in percent "
          "(20-100). With both, the first failure is the reply.")
      .def(
          "set_force_async",
          [](PyHand& h, std::int32_t closing, std::optional<std::int32_t> opening, Seconds t) {
            return async_call(
                [&] { return h.hand().set_force_async(closing, opening, to_timeout(t)); });
          },
          "closing"_a, "opening"_a = py::none(), timeout_arg)
      .def(
          "grasp",
          [](PyHand& h, std::int32_t force, Seconds t) {
            return blocking_call([&] { return h.hand().grasp_async(force, to_timeout(t)); });
          },
          "force"_a, timeout_arg,
          "Closes with force percent: reply.grasp is GRASPED (stopped on an object) or MISSED "
          "(closed on nothing); reply.value the final position.")
      .def(
          "grasp_async",
          [](PyHand& h, std::int32_t force, Seconds t) {
            return async_call([&] { return h.hand().grasp_async(force, to_timeout(t)); });
          },
          "force"_a, timeout_arg)
      .def(
          "release",
          [](PyHand& h, std::int32_t position, Seconds t) {
            return blocking_call([&] { return h.hand().release_async(position, to_timeout(t)); });
          },
          "position"_a, timeout_arg, "Opens to position; the reply comes once arrived.")
      .def(
          "release_async",
          [](PyHand& h, std::int32_t position, Seconds t) {
            return async_call([&] { return h.hand().release_async(position, to_timeout(t)); });
          },
          "position"_a, timeout_arg)
      .def(
          "stop",
          [](PyHand& h, Seconds t) {
            return blocking_call([&] { return h.hand().stop_async(to_timeout(t)); });
          },
          timeout_arg, "Holds the current position; pending motion ends CANCELLED.")
      .def(
          "stop_async",
          [](PyHand& h, Seconds t) {
            return async_call([&] { return h.hand().stop_async(to_timeout(t)); });
          },
          timeout_arg)
      .def(
          "read",
          [](PyHand& h, std::uint16_t code, Seconds t) {
            return blocking_call([&] { return h.hand().read_async(code, to_timeout(t)); });
          },
          "register_code"_a, timeout_arg,
          "Reads a register (dh3.reg.position, ...); reply.value is what was read.")
      .def(
          "read_async",
          [](PyHand& h, std::uint16_t code, Seconds t) {
            return async_call([&] { return h.hand().read_async(code, to_timeout(t)); });
          },
          "register_code"_a, timeout_arg)
      .def(
          "set_can_id",
          [](PyHand& h, std::int32_t id, Seconds t) {
            return blocking_call([&] { return h.hand().set_can_id_async(id, to_timeout(t)); });
          },
          "can_id"_a, timeout_arg,
          "Administrative (the service must allow it; the hand needs a reboot after).")
      .def(
          "set_can_id_async",
          [](PyHand& h, std::int32_t id, Seconds t) {
            return async_call([&] { return h.hand().set_can_id_async(id, to_timeout(t)); });
          },
          "can_id"_a, timeout_arg)
      .def(
          "set_baud_rate",
          [](PyHand& h, std::int32_t index, Seconds t) {
            return blocking_call(
                [&] { return h.hand().set_baud_rate_async(index, to_timeout(t)); });
          },
          "index"_a, timeout_arg, "Administrative: baud rate index 0 (500 kbps) - 5 (100 kbps).")
      .def(
          "set_baud_rate_async",
          [](PyHand& h, std::int32_t index, Seconds t) {
            return async_call([&] { return h.hand().set_baud_rate_async(index, to_timeout(t)); });
          },
          "index"_a, timeout_arg)
      .def(
          "scan_bus",
          [](PyHand& h, Seconds t) {
            return blocking_call([&] { return h.hand().scan_bus_async(to_timeout(t)); });
          },
          timeout_arg, "Probes this hand's whole bus for hands now; reply.found_ids lists them.")
      .def(
          "scan_bus_async",
          [](PyHand& h, Seconds t) {
            return async_call([&] { return h.hand().scan_bus_async(to_timeout(t)); });
          },
          timeout_arg)
      .def(
          "acquire_lease",
          [](PyHand& h, double ttl, Seconds t) {
            const auto ms = to_milliseconds(ttl, "ttl");
            return blocking_call([&] { return h.hand().acquire_lease_async(ms, to_timeout(t)); });
          },
          "ttl"_a, timeout_arg,
          "Leases: while this client holds one (ttl seconds), other clients' motion and write "
          "commands to the hand are DENIED. A lease ends on release, on expiry, or when this "
          "client leaves the domain.")
      .def(
          "acquire_lease_async",
          [](PyHand& h, double ttl, Seconds t) {
            const auto ms = to_milliseconds(ttl, "ttl");
            return async_call([&] { return h.hand().acquire_lease_async(ms, to_timeout(t)); });
          },
          "ttl"_a, timeout_arg)
      .def(
          "renew_lease",
          [](PyHand& h, double ttl, Seconds t) {
            const auto ms = to_milliseconds(ttl, "ttl");
            return blocking_call([&] { return h.hand().renew_lease_async(ms, to_timeout(t)); });
          },
          "ttl"_a, timeout_arg)
      .def(
          "renew_lease_async",
          [](PyHand& h, double ttl, Seconds t) {
            const auto ms = to_milliseconds(ttl, "ttl");
            return async_call([&] { return h.hand().renew_lease_async(ms, to_timeout(t)); });
          },
          "ttl"_a, timeout_arg)
      .def(
          "release_lease",
          [](PyHand& h, Seconds t) {
            return blocking_call([&] { return h.hand().release_lease_async(to_timeout(t)); });
          },
          timeout_arg)
      .def(
          "release_lease_async",
          [](PyHand& h, Seconds t) {
            return async_call([&] { return h.hand().release_lease_async(to_timeout(t)); });
          },
          timeout_arg)
      .def(
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

  py::class_<PyClient>(m, "Client",
                       "Finds DH-3 hands on a DDS domain and drives them. Never raises on "
                       "creation: check connected() and error(). A Client and its Hands may be "
                       "used from any number of threads at once.")
      .def(py::init([](int domain, std::string participant_name, std::string xml_profile_file,
                       std::string xml_profile, std::vector<std::string> interfaces, bool udp_only,
                       std::vector<std::string> discovery_servers, std::string security_dir,
                       std::string security_identity, double default_timeout) {
             dh3::ClientOptions options;
             options.domain = domain;
             options.participant_name = std::move(participant_name);
             options.xml_profile_file = std::move(xml_profile_file);
             options.xml_profile = std::move(xml_profile);
             options.interfaces = std::move(interfaces);
             options.udp_only = udp_only;
             options.discovery_servers = std::move(discovery_servers);
             options.security_dir = std::move(security_dir);
             options.security_identity = std::move(security_identity);
             options.default_timeout = to_milliseconds(default_timeout, "default_timeout");
             return std::make_unique<PyClient>(std::move(options));
           }),
           py::kw_only(), "domain"_a = 0, "participant_name"_a = "dh3-client",
           "xml_profile_file"_a = "", "xml_profile"_a = "",
           "interfaces"_a = std::vector<std::string>{}, "udp_only"_a = false,
           "discovery_servers"_a = std::vector<std::string>{}, "security_dir"_a = "",
           "security_identity"_a = "operator", "default_timeout"_a = 10.0,
           "Joins the DDS domain. domain: 0-232. interfaces: IPv4 addresses of network "
           "interfaces (empty: loopback only; [\"*\"]: all). udp_only: no shared-memory "
           "transport. discovery_servers: \"HOST[:PORT]\" each. xml_profile_file/xml_profile: a "
           "Fast DDS XML profile (replaces interfaces and udp_only). security_dir/"
           "security_identity: DDS Security credentials. default_timeout: seconds for calls "
           "given no timeout.")
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
      .def("error",
           [](PyClient& c) {
             auto client = c.current();
             if (!client) return std::string("the client is closed");
             py::gil_scoped_release released;
             return client->error();
           })
      .def(
          "read_only",
          [](PyClient& c) {
            auto client = c.client();
            py::gil_scoped_release released;
            return client->read_only();
          },
          "True when DDS Security refused this client commands: every command ends DENIED.")
      .def("client_id",
           [](PyClient& c) {
             auto client = c.client();
             py::gil_scoped_release released;
             return client->client_id();
           })
      .def("domain", [](PyClient& c) { return c.client()->domain(); })
      .def(
          "default_timeout",
          [](PyClient& c) {
            return std::chrono::duration<double>(c.client()->default_timeout()).count();
          },
          "Seconds.")
      .def(
          "services",
          [](PyClient& c) {
            auto client = c.client();
            py::gil_scoped_release released;
            return client->services();
          },
          "Every service seen on the domain (ready says which are here now).")
      .def(
          "service",
          [](PyClient& c, const std::string& name) {
            auto client = c.client();
            py::gil_scoped_release released;
            return client->service(name);
          },
          "name"_a)
      .def(
          "hands",
          [](PyClient& c) {
            auto client = c.client();
            py::gil_scoped_release released;
            return client->hands();
          },
          "The latest status of every hand seen.")
      .def(
          "status",
          [](PyClient& c, const dh3::HandAddress& address) {
            auto client = c.client();
            py::gil_scoped_release released;
            return client->status(address);
          },
          "address"_a)
      .def(
          "wait_for_service",
          [](PyClient& c, const std::string& name, Seconds t) {
            return value_or_raise(
                c.wait_in_slices<dh3::ServiceInfo>(t, [&](dh3::Client& client, Milliseconds slice) {
                  return client.wait_for_service(name, slice);
                }));
          },
          "name"_a = "", timeout_arg,
          "Waits until the named service (empty: any) is ready; raises dh3.Error(NO_SERVICE) "
          "on timeout.")
      .def(
          "wait_for_statuses",
          [](PyClient& c, Seconds t) {
            const auto deadline = Clock::now() + c.effective(t);
            for (;;) {
              const auto left = std::chrono::duration_cast<Milliseconds>(deadline - Clock::now());
              bool done = false;
              auto client = c.client();  // anew each slice: close() ends the wait
              {
                py::gil_scoped_release released;
                done = client->wait_for_statuses(std::clamp(left, Milliseconds(1), kSlice));
              }
              if (done || left <= kSlice) return done;
              check_signals();
            }
          },
          timeout_arg,
          "Waits until every ready service's hands have a status here; True if so in time.")
      .def(
          "hand",
          [](PyClient& c, const dh3::HandAddress& address) {
            return c.wrap(c.client()->hand(address));
          },
          "address"_a, "A hand by address; no lookup, no waiting.")
      .def(
          "find_hand",
          [](PyClient& c, const std::string& spec) {
            auto client = c.client();
            std::optional<dh3::Found<dh3::Hand>> found;
            {
              py::gil_scoped_release released;
              found.emplace(client->find_hand(spec));
            }
            return c.wrap(value_or_raise(std::move(*found)));
          },
          "spec"_a,
          "A hand by \"SERVICE/BUS/ID\", \"BUS/ID\", \"ID\" or name among the hands known now; "
          "raises dh3.Error otherwise.")
      .def(
          "wait_for_hand",
          [](PyClient& c, const std::string& spec, Seconds t) {
            return c.wrap(value_or_raise(
                c.wait_in_slices<dh3::Hand>(t, [&](dh3::Client& client, Milliseconds slice) {
                  return client.wait_for_hand(spec, slice);
                })));
          },
          "spec"_a, timeout_arg,
          "Waits until spec names exactly one hand whose status this client has. Raises "
          "dh3.Error: NO_SERVICE if its service never appeared, UNKNOWN_HAND if the service is "
          "here but has no such hand, INVALID_ARGUMENT for bad or ambiguous specs.")
      .def(
          "scan",
          [](PyClient& c, const std::string& service, const std::string& bus, Seconds t) {
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
          [](PyClient& c, const std::string& service, const std::string& bus, Seconds t) {
            auto client = c.client();
            return async_call([&] { return client->scan_async(service, bus, to_timeout(t)); });
          },
          "service"_a, "bus"_a, timeout_arg)
      .def(
          "subscribe",
          [](PyClient& c, py::function callback, std::optional<dh3::HandAddress> only) {
            auto client = c.client();
            auto cb = python_callback<dh3::HandEvent>(std::move(callback), "dh3: event callback");
            py::gil_scoped_release released;
            return std::make_unique<PySubscription>(client->subscribe(std::move(cb), only));
          },
          "callback"_a, "only"_a = py::none(),
          "Calls callback(event) for every event of every hand (or of only) from now on, on the "
          "client's thread. Keep the returned Subscription.")
      .def(
          "subscribe_status",
          [](PyClient& c, py::function callback, std::optional<dh3::HandAddress> only) {
            auto client = c.client();
            auto cb = python_callback<dh3::HandStatus>(std::move(callback), "dh3: status callback");
            py::gil_scoped_release released;
            return std::make_unique<PySubscription>(client->subscribe_status(std::move(cb), only));
          },
          "callback"_a, "only"_a = py::none(),
          "Calls callback(status) for every new status sample (the ones already received "
          "first) of every hand or of only. Keep the returned Subscription.");
}
