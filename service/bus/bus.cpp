#include "bus/bus.hpp"

namespace dh3::bus {

std::string_view to_string(BusError error) {
  switch (error) {
    case BusError::link_down:
      return "link_down";
    case BusError::io_error:
      return "io_error";
    case BusError::frame_invalid:
      return "frame_invalid";
    case BusError::would_block:
      return "would_block";
  }
  return "unknown";
}

}  // namespace dh3::bus
