// ClientCore's life cycle: set up, connected, closed. Its other jobs have a
// file each: client_endpoints (DDS wiring), pending_calls, service_tracker,
// status_cache, subscriptions, dispatcher.

#include "client_core.hpp"

#include "client_endpoints.hpp"

namespace dh3::detail {

ClientCore::ClientCore(ClientOptions options) : ClientCore(std::move(options), EndpointCreator{}) {}

ClientCore::ClientCore(ClientOptions options, const EndpointCreator& endpoints)
    : options_(std::move(options)) {
  dds_ = std::make_unique<Dds>(*this);
  if (auto set_up = set_up_dds(endpoints); !set_up) {
    error_ = std::move(set_up).error();
    dds_.reset();
    closed_ = true;
    return;
  }
  io_thread_ = std::thread([this] { io_loop(); });
}

ClientCore::~ClientCore() {
  close();
}

bool ClientCore::connected() const {
  std::lock_guard lock(mutex_);
  return !closed_;
}

void ClientCore::close() {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_ && !io_thread_.joinable() && dds_ == nullptr) return;
    closed_ = true;
    for (auto& [seq, pending] : pending_) {
      out.completions.emplace_back(std::move(pending.done),
                                   make_reply(Code::not_connected, "the client was closed"));
    }
    pending_.clear();
    to_write_.clear();
    close_group_calls_locked();
  }
  io_wake_.notify_all();
  changed_.notify_all();
  // The io thread is the only writer: once it is gone no write can race the
  // deletion below.
  if (io_thread_.joinable()) io_thread_.join();
  {
    // Callers writing their own requests finish before the writer goes.
    std::unique_lock lock(mutex_);
    writes_done_.wait(lock, [this] { return writes_in_flight_ == 0; });
  }
  run(out);
  dds_.reset();  // waits for listener callbacks in progress
  dispatcher_.stop();
}

}  // namespace dh3::detail
