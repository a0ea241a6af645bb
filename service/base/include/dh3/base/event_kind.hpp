#pragma once
// The kinds of hand event, one list for each layer that speaks of them: the
// hand layer makes them (dh3::hand::EventKind), the service publishes them as
// the wire's msg::EventKind (idl/dh3.idl), and the client library hands them
// to programs (dh3::EventKind in dh3/types.hpp). Plain C++17, as the client's
// public headers include it: it is installed with them.

#include <cstdint>

namespace dh3 {

enum class EventKind : std::uint8_t {
  online,
  offline,
  initialized,
  init_failed,
  arrived,
  grasped,
  missed,
  dropped,
  rotation_arrived,
  rotation_blocked,
  fault,
  /// Made by the client library, never by the hand layer or sent by a
  /// service: another process serves the hand's service now (a standby took
  /// over, a restart); the message says which, and which one served it before.
  taken_over,
};

}  // namespace dh3
