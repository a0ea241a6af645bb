#include "support.hpp"

#include <algorithm>
#include <cmath>

namespace dh3::python {

py::object python_enum_class(const char* name) {
  return py::module_::import("dh3").attr(name);
}

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

void raise_error(dh3::Code code, const std::string& message) {
  py::object error = python_enum_class("Error")(py::cast(code), message);
  PyErr_SetObject(error.get_type().ptr(), error.ptr());
  throw py::error_already_set();
}

void check_signals() {
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

namespace {

struct PyObjectDeleter {
  void operator()(py::object* object) const {
    if (!Py_IsInitialized()) return;
    py::gil_scoped_acquire gil;
    delete object;
  }
};

}  // namespace

SharedPyObject share(py::object object) {
  return SharedPyObject(new py::object(std::move(object)), PyObjectDeleter{});
}

}  // namespace dh3::python
