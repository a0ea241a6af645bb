#pragma once
// Group calls (dh3/group.hpp): one GroupRequest on its own topic, one
// GroupReply. Simpler than single calls (pending_calls.hpp) on purpose: the
// calling thread writes the request itself and waits for the reply; one that
// does not come by the deadline ends it NO_REPLY, and the loss of the service
// instance it was sent to ends it SERVICE_LOST at once, as for single calls.
//
// Thread-safe: its own mutex is taken last (ClientCore may hold its state mutex)
// and a reply reaches its waiting caller (a promise) after it is released.

#include <cstdint>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "dh3/base/result.hpp"
#include "dh3/client.hpp"
#include "dh3/group.hpp"
#include "dh3_idl/dh3.h"

namespace dh3::detail {

class GroupCalls {
 public:
  /// The request as it goes out (without client_id and request_seq), or why it
  /// cannot: the hands must be of one service, and each must pass the
  /// contract's limits as a single command would.
  [[nodiscard]] static Result<msg::GroupRequest, GroupReply> make_request(
      GroupCommand command, const std::vector<HandAddress>& hands, std::int32_t value,
      Timeout timeout);
  [[nodiscard]] static GroupReply refused(Code code, std::string message);

  [[nodiscard]] static GroupReply reply_of(const msg::GroupReply& reply);

  /// Files a call under `seq`, sent to the service instance `sent_to` (its
  /// participant's prefix) as `what` ("GROUP MOVE of 2 hands"); its reply,
  /// lose() or close() fulfils the future.
  std::future<GroupReply> add(std::uint64_t seq, std::string sent_to, std::string what);
  /// The promise of the call `seq`, no longer filed; nullptr if none waits.
  std::shared_ptr<std::promise<GroupReply>> take(std::uint64_t seq);
  /// Drops a call that gave up; false if its reply came first (the future has it).
  bool forget(std::uint64_t seq);
  /// Ends the calls sent to the instance `lost` SERVICE_LOST, saying `why`.
  void lose(const std::string& lost, const std::string& why);
  /// Ends every call NOT_CONNECTED.
  void close();

 private:
  struct Pending {
    std::shared_ptr<std::promise<GroupReply>> promise;
    std::string sent_to;
    std::string what;
  };
  std::mutex mutex_;  ///< guards pending_
  std::map<std::uint64_t, Pending> pending_;
};

}  // namespace dh3::detail
