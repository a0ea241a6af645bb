#pragma once
// Simulated DH-3 hands served as the vendor's transfer box over TCP: clients
// send 14-byte frames (FF FE FD FC, gripper ID, 8-byte payload, FB) and get the
// hands' replies the same way. The heart of `dh3-sim`, a class so tests can
// run it in-process too.
//
// Several clients may be connected: a reply goes to the connection that sent
// the request, unsolicited frames (initialization finished) to every one.
// Requests to an ID without a hand get no reply, as on a real bus.
//
// An optional control channel (a file descriptor, stdin for dh3-sim) takes one
// command per line and answers each with one line starting with "ok" or
// "error"; see kControlHelp. The answers let a test know the command took
// effect before it sends its next frame.
//
// Threading: run() serves everything on the calling thread with poll(); only
// request_stop() may be called from elsewhere (also from a signal handler).

#include <atomic>
#include <cstdint>
#include <memory>
#include <queue>
#include <string>
#include <string_view>
#include <vector>

#include "common/clock.hpp"
#include "common/result.hpp"
#include "protocol/stream_decoder.hpp"
#include "sim/hand_set.hpp"
#include "sim/sim_hand.hpp"

namespace dh3::sim {

struct TransferBoxServerOptions {
  /// IPv4 address to listen on ("localhost" means 127.0.0.1).
  std::string host = "127.0.0.1";
  /// 0 picks a free port; port() tells which.
  std::uint16_t port = 0;
  std::vector<SimHandOptions> hands;
  /// Control commands come from here, one per line; -1: no control channel.
  /// End of file closes the channel, the server goes on.
  int control_in = -1;
  /// Answers to control commands go here, one line each; -1: not written.
  int control_out = -1;
  /// A client that does not read its replies is disconnected when this much
  /// is waiting for it.
  std::size_t max_pending_bytes = 1U << 20;
};

enum class ServerError : std::uint8_t {
  bad_address,    ///< host is not an IPv4 address
  socket_failed,  ///< the OS refused a socket or pipe
  bind_failed,    ///< address in use or not ours
  listen_failed,
};

[[nodiscard]] std::string_view to_string(ServerError error);

/// The control commands, for --help.
extern const std::string_view kControlHelp;

class TransferBoxServer {
 public:
  /// Binds and listens; the hands start now (not initialized).
  [[nodiscard]] static Result<std::unique_ptr<TransferBoxServer>, ServerError> open(
      TransferBoxServerOptions options, const Clock& clock);
  ~TransferBoxServer();
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
  void request_stop();

  /// Executes one control command and returns its answer line (no newline).
  /// Only on run()'s thread, or while run() is not running.
  std::string execute(std::string_view command);

 private:
  struct Client {
    int fd = -1;
    std::uint64_t id = 0;
    std::string peer;
    protocol::StreamDecoder decoder;
    std::vector<std::uint8_t> out;  ///< bytes not yet taken by the socket
  };
  /// A frame to send at `due`; client_id 0 means every client.
  struct Scheduled {
    TimePoint due;
    std::uint64_t sequence = 0;
    std::uint64_t client_id = 0;
    protocol::Message message;
  };
  struct ScheduledLater {
    bool operator()(const Scheduled& a, const Scheduled& b) const {
      return a.due != b.due ? a.due > b.due : a.sequence > b.sequence;
    }
  };

  TransferBoxServer(TransferBoxServerOptions options, const Clock& clock);
  [[nodiscard]] Result<void, ServerError> listen();

  void serve_due(TimePoint now);
  void schedule(const std::vector<Outgoing>& frames, std::uint64_t client_id);
  [[nodiscard]] int poll_timeout_ms(TimePoint now) const;
  void accept_clients();
  void read_client(Client& client);
  void write_client(Client& client);
  void queue_for(Client& client, const protocol::Message& message);
  void close_client(Client& client, std::string_view why);
  void read_control();
  void answer_control(const std::string& line);
  void kick_all();
  /// The hand answering on `id`, advanced to now (its unsolicited frames sent).
  SimHand* hand_now(std::uint8_t id);

  TransferBoxServerOptions options_;
  const Clock& clock_;
  HandSet hands_;
  int listen_fd_ = -1;
  int wake_pipe_[2] = {-1, -1};
  std::uint16_t port_ = 0;
  std::atomic<bool> stop_requested_{false};
  std::vector<std::unique_ptr<Client>> clients_;
  std::uint64_t next_client_id_ = 1;
  std::priority_queue<Scheduled, std::vector<Scheduled>, ScheduledLater> scheduled_;
  std::uint64_t next_sequence_ = 0;
  std::vector<Outgoing> replies_;           // scratch
  std::vector<Outgoing> unsolicited_;       // scratch
  std::vector<protocol::Message> decoded_;  // scratch
  std::string control_buffer_;
};

}  // namespace dh3::sim
