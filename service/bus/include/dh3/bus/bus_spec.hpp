#pragma once
// Bus specs as users write them (command line, config file) and the factory
// that opens the matching backend of this layer (a sim spec is parsed here; the
// simulated bus itself lives in the sim layer above, see dh3/sim/sim_bus.hpp):
//
//   sim                         one simulated hand with CAN ID 1
//   sim:1,2,3 or sim:1-4,7      simulated hands with these CAN IDs (1-255)
//   socketcan:can0              a SocketCAN interface
//   tcp:HOST:PORT               a transfer box over TCP ("tcp:[::1]:9000" for IPv6)
//   serial:DEVICE[@BAUD]        a transfer box on a serial line, 8N1, default 115200

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/base/result.hpp"
#include "dh3/bus/bus.hpp"
#include "dh3/bus/socketcan_bus.hpp"
#include "dh3/bus/stream_link.hpp"
#include "dh3/bus/transfer_box_bus.hpp"

namespace dh3::bus {

enum class BusKind : std::uint8_t { sim, socketcan, tcp, serial };

[[nodiscard]] std::string_view to_string(BusKind kind);

inline constexpr std::uint32_t kDefaultSerialBaudRate = 115200;

/// A parsed spec. Only the fields of its kind are set.
struct BusSpec {
  BusKind kind = BusKind::sim;
  std::vector<std::uint8_t> sim_hand_ids;  ///< sim: in the order given
  std::string interface;                   ///< socketcan
  std::string host;                        ///< tcp: name or address, IPv6 without brackets
  std::uint16_t port = 0;                  ///< tcp
  std::string device;                      ///< serial: path
  std::uint32_t baud_rate = 0;             ///< serial

  friend bool operator==(const BusSpec&, const BusSpec&) = default;
};

/// Parses a spec; the error says what is wrong and what was expected, e.g.
/// "bad bus spec 'tcp:box': missing port (expected tcp:HOST:PORT)".
[[nodiscard]] Result<BusSpec, std::string> parse_bus_spec(std::string_view text);

/// True if `text` names a bus simulated inside this process ("sim", "sim:1,2"),
/// which no other process can reach; false for every other kind and for a bad spec.
[[nodiscard]] bool is_simulated(std::string_view text);

/// The canonical text of a spec ("sim:1,2", "tcp:[::1]:9000", "serial:/dev/ttyS0@9600").
[[nodiscard]] std::string to_string(const BusSpec& spec);

/// Tuning for every backend open_bus() may create.
struct OpenBusOptions {
  SocketCanOptions socketcan;
  TransferBoxOptions transfer_box;
  TcpLinkOptions tcp;
};

/// Opens the backend a spec names. Fails with a clear message for a bad spec, a
/// sim spec (the sim layer makes those buses) or what cannot get better by
/// waiting (no CAN support in the kernel). A box that
/// is not reachable yet, a missing serial device or a down CAN interface give a
/// bus whose link is down and which keeps retrying.
[[nodiscard]] Result<std::unique_ptr<Bus>, std::string> open_bus(
    std::string_view spec, const Clock& clock, const OpenBusOptions& options = {});
[[nodiscard]] Result<std::unique_ptr<Bus>, std::string> open_bus(
    const BusSpec& spec, const Clock& clock, const OpenBusOptions& options = {});

}  // namespace dh3::bus
