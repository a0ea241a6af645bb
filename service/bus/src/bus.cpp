#include "dh3/bus/bus.hpp"

namespace dh3::bus {

Result<std::size_t, BusError> Bus::send_burst(std::span<const CanFrame> frames) {
  std::size_t taken = 0;
  for (const CanFrame& frame : frames) {
    if (auto sent = send(frame); !sent) {
      if (taken == 0) return dh3::fail(sent.error());
      break;
    }
    ++taken;
  }
  return taken;
}

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
    case BusError::not_permitted:
      return "not_permitted";
  }
  return "unknown";
}

std::string_view to_string(ErrorFrameKind kind) {
  switch (kind) {
    case ErrorFrameKind::bus_off:
      return "bus_off";
    case ErrorFrameKind::error_passive:
      return "error_passive";
    case ErrorFrameKind::error_warning:
      return "error_warning";
    case ErrorFrameKind::error_active:
      return "error_active";
    case ErrorFrameKind::controller_overflow:
      return "controller_overflow";
    case ErrorFrameKind::restarted:
      return "restarted";
    case ErrorFrameKind::tx_timeout:
      return "tx_timeout";
    case ErrorFrameKind::lost_arbitration:
      return "lost_arbitration";
    case ErrorFrameKind::protocol_violation:
      return "protocol_violation";
    case ErrorFrameKind::transceiver:
      return "transceiver";
    case ErrorFrameKind::no_ack:
      return "no_ack";
    case ErrorFrameKind::bus_error:
      return "bus_error";
  }
  return "unknown";
}

}  // namespace dh3::bus
