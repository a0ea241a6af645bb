// dh3._dh3: the Python binding of libdh3client. The package dh3
// (dh3/__init__.py) re-exports these names and defines the enums as Python
// enum.IntEnum classes and the exception dh3.Error; support.hpp converts to
// and from them at the boundary and states the rules on threads and the GIL.

#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_dh3, m) {
  m.doc() = "The compiled part of dh3 (libdh3client); import dh3 instead, which re-exports these.";
  dh3::python::bind_functions(m);
  dh3::python::bind_values(m);
  dh3::python::bind_hand(m);
  dh3::python::bind_client(m);
}
