// The module's free functions: enum spellings, the register map, exit.

#include <pybind11/stl.h>

#include <cstdint>
#include <string>

#include "bindings.hpp"
#include "calls.hpp"
#include "dh3/registers.hpp"
#include "py_client.hpp"
#include "support.hpp"

namespace dh3::python {

namespace {

using namespace pybind11::literals;

/// An enum value as libdh3client spells it; `kind` names the enum.
std::string enum_to_string(const std::string& kind, int number) {
  if (kind == "Code") return std::string(dh3::to_string(static_cast<dh3::Code>(number)));
  if (kind == "GraspOutcome")
    return std::string(dh3::to_string(static_cast<dh3::GraspOutcome>(number)));
  if (kind == "GripState") return std::string(dh3::to_string(static_cast<dh3::GripState>(number)));
  if (kind == "RotationState")
    return std::string(dh3::to_string(static_cast<dh3::RotationState>(number)));
  if (kind == "EventKind") return std::string(dh3::to_string(static_cast<dh3::EventKind>(number)));
  throw py::value_error("no enum " + kind);
}

/// Closes every client and waits for the threads that complete Futures, so
/// none of them runs while Python shuts down.
void shutdown(double seconds) {
  close_every_client();
  wait_for_futures(to_milliseconds(seconds, "timeout"));
}

}  // namespace

void bind_functions(py::module_& m) {
  m.def(
      "to_string", [](dh3::Code c) { return std::string(dh3::to_string(c)); }, "code"_a);
  m.def("_to_string", &enum_to_string,
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
}

}  // namespace dh3::python
