#pragma once
// Group calls (dh3/group.hpp): the GroupRequest a call writes on its own
// topic, and the GroupReply it ends with. The calls themselves wait in
// PendingCalls beside single calls (pending_calls.hpp): written once the
// service's group endpoints matched, ended NO_REPLY at their deadline and
// SERVICE_LOST when the service instance they were sent to is lost.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "dh3/base/result.hpp"
#include "dh3/client.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/group.hpp"
#include "pending_calls.hpp"

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

  /// The call PendingCalls files (without deadline, client_id and
  /// request_seq), bounded by `limit`; `done` takes its reply or, adapted,
  /// any other end. Or make_request()'s refusal (`done` not called).
  [[nodiscard]] static Result<PendingCalls::Call, GroupReply> make_call(
      GroupCommand command, const std::vector<HandAddress>& hands, std::int32_t value,
      Timeout timeout, std::chrono::milliseconds limit, PendingCalls::GroupDone done);
};

}  // namespace dh3::detail
