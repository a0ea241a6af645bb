#pragma once
// Simulated DH-3 hands served as the vendor's transfer box over TCP: clients
// send 14-byte frames (FF FE FD FC, gripper ID, 8-byte payload, FB) and get the
// hands' replies the same way. One of dh3-sim's transports (the other is
// CanServer); a class so tests can run it in-process too.
//
// Several clients may be connected: a reply goes to the connection that sent
// the request, unsolicited frames (initialization finished) to every one.
// Shared (--shared), it behaves as a CAN bus does: every client receives every
// frame, the other clients' requests and every reply, so a standby service
// watches the primary through it. Whether the vendor's box accepts a second
// client at all is not known (docs/hot-standby.md).
// Requests to an ID without a hand get no reply, as on a real bus.
//
// The hands, the control channel (see kControlHelp; `kick` is this transport's
// own command) and the interval check are SimHost's. For the interval check a
// frame's time is the kernel's receive timestamp of the read that carried it
// (the time of reading where there is none): TCP carries no send time, so
// frames that arrive together count as sent together.
//
// Threading: run() serves everything on the calling thread with poll(); only
// request_stop() may be called from elsewhere (also from a signal handler).

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/base/fd_util.hpp"
#include "dh3/base/result.hpp"
#include "dh3/protocol/stream_decoder.hpp"
#include "dh3/sim_server/sim_host.hpp"

namespace dh3::sim {

/// The hands, control channel and interval check (SimHostOptions) and where to listen.
struct TransferBoxServerOptions : SimHostOptions {
  /// IPv4 address to listen on ("localhost" means 127.0.0.1).
  std::string host = "127.0.0.1";
  /// 0 picks a free port; port() tells which.
  std::uint16_t port = 0;
  /// A client that does not read its replies is disconnected when this much
  /// is waiting for it.
  std::size_t max_pending_bytes = 1U << 20;
  /// Every client receives every frame: requests of the others and all replies.
  bool shared = false;
};

enum class ServerError : std::uint8_t {
  bad_address,    ///< host is not an IPv4 address
  socket_failed,  ///< the OS refused a socket or pipe
  bind_failed,    ///< address in use or not ours
  listen_failed,
};

[[nodiscard]] std::string_view to_string(ServerError error);

class TransferBoxServer final : private SimTransport {
 public:
  /// Binds and listens; the hands start now (not initialized).
  [[nodiscard]] static Result<std::unique_ptr<TransferBoxServer>, ServerError> open(
      TransferBoxServerOptions options, const Clock& clock);
  TransferBoxServer(const TransferBoxServer&) = delete;
  TransferBoxServer& operator=(const TransferBoxServer&) = delete;

  /// The port actually listened on.
  [[nodiscard]] std::uint16_t port() const { return port_; }
  /// "127.0.0.1:45678".
  [[nodiscard]] std::string address() const;

  /// Serves clients, hands and the control channel until request_stop() or a
  /// `quit` command, then closes every client connection.
  void run();

  /// Makes run() return soon. Any thread; async-signal-safe.
  void request_stop() { host_.request_stop(); }

  /// Executes one control command and returns its answer line (no newline).
  /// Only on run()'s thread, or while run() is not running.
  std::string execute(std::string_view command) { return host_.execute(command, *this); }

  /// Interval violations over all hands so far (run()'s thread, or after it).
  [[nodiscard]] std::uint64_t interval_violations() const { return host_.interval_violations(); }

 private:
  struct Client {
    UniqueFd fd;
    std::uint64_t id = 0;
    std::string peer;
    protocol::StreamDecoder decoder;
    std::vector<std::uint8_t> out;  ///< bytes not yet taken by the socket
  };

  TransferBoxServer(TransferBoxServerOptions options, const Clock& clock);
  [[nodiscard]] Result<void, ServerError> listen();

  // SimTransport
  void add_poll_fds(std::vector<pollfd>& fds) override;
  void on_poll(std::span<const pollfd> fds) override;
  void send(std::uint64_t destination, const protocol::Message& message) override;
  void flush() override;
  std::optional<std::string> execute_own(std::span<const std::string_view> words) override;
  void on_stop() override { kick_all(); }

  void accept_clients();
  void read_client(Client& client);
  void write_client(Client& client);
  void queue_for(Client& client, const protocol::Message& message);
  /// Shared: a client's request goes to every other client too.
  void share_request(const Client& sender, const protocol::Message& request);
  void close_client(Client& client, std::string_view why);
  void kick_all();

  TransferBoxServerOptions options_;
  SimHost host_;
  UniqueFd listen_fd_;
  std::uint16_t port_ = 0;
  std::vector<std::unique_ptr<Client>> clients_;
  std::uint64_t next_client_id_ = 1;
  std::vector<protocol::Message> decoded_;  // scratch
};

}  // namespace dh3::sim
