#pragma once
// The parts of dh3._dh3, each adding its names to the module. PYBIND11_MODULE
// calls them in this order: a type is registered before the functions that
// take or return it, so their docstrings name it the Python way.

#include <pybind11/pybind11.h>

namespace dh3::python {

/// to_string, the register map (dh3.reg, register_name, ...), _shutdown.
void bind_functions(pybind11::module_& m);
/// HandAddress (and parse_hand_address), Reply, HandStatus, HandEvent,
/// HandInfo, BusInfo, ServiceInfo, Subscription.
void bind_values(pybind11::module_& m);
void bind_hand(pybind11::module_& m);
void bind_client(pybind11::module_& m);

}  // namespace dh3::python
