#pragma once
// What every part of dh3._dh3 shares: the enum casters, timeouts in seconds,
// dh3.Error, and the GIL rules the binding keeps.
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
#include <pybind11/pybind11.h>

#include <chrono>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "dh3/client.hpp"
#include "dh3/types.hpp"

namespace dh3::python {

namespace py = pybind11;

using Milliseconds = std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;

/// How long a blocking call waits with the GIL released before it checks for
/// signals: short enough that Ctrl-C feels immediate.
inline constexpr Milliseconds kSlice{50};

/// dh3.NAME: the enums and dh3.Error are defined in dh3/__init__.py.
py::object python_enum_class(const char* name);

// ---------------------------------------------------------------------------
// Timeouts: seconds as float in Python; None = the client's default.

using OptionalSeconds = std::optional<double>;

/// Raises ValueError unless `seconds` is finite and >= 0; `what` names it.
Milliseconds to_milliseconds(double seconds, const char* what);
/// Zero (the client's default) for None.
dh3::Timeout to_timeout(const OptionalSeconds& seconds);

/// Raises dh3.Error(code, message).
[[noreturn]] void raise_error(dh3::Code code, const std::string& message);

template <typename T>
T value_or_raise(dh3::Found<T> found) {
  if (!found) raise_error(found.code(), found.message());
  return std::move(found.value());
}

/// Raises the pending Python exception (KeyboardInterrupt, ...) if a signal
/// handler raised one. The GIL must be held.
void check_signals();

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

using SharedPyObject = std::shared_ptr<py::object>;
SharedPyObject share(py::object object);

}  // namespace dh3::python

// Enums: dh3.Code & co. are enum.IntEnum classes defined in dh3/__init__.py;
// the casters below turn the C++ enums into members of those classes and
// accept any int (an IntEnum member is one) coming back. Every translation
// unit of the module sees them through this header.
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
      return dh3::python::python_enum_class(PyName)(static_cast<int>(source)).release();    \
    }                                                                                       \
  };                                                                                        \
  }

DH3_PYTHON_ENUM_CASTER(dh3::Code, "Code")
DH3_PYTHON_ENUM_CASTER(dh3::GraspOutcome, "GraspOutcome")
DH3_PYTHON_ENUM_CASTER(dh3::GripState, "GripState")
DH3_PYTHON_ENUM_CASTER(dh3::RotationState, "RotationState")
DH3_PYTHON_ENUM_CASTER(dh3::EventKind, "EventKind")
DH3_PYTHON_ENUM_CASTER(dh3::GroupCommand, "GroupCommand")
