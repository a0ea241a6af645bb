#pragma once
// Group requests: one command for several hands, all or none
// (group_validation.hpp), their motion frames released together by the hand
// layer (hand/group_release.hpp), one reply once every hand's command ended.
//
// Threading: handle() on the group listener's thread, one at a time (the
// Service's dispatch lock); members end on bus loops; writes under no lock of its own.

#include <string>
#include <vector>

#include "client_rate.hpp"
#include "dh3/base/clock.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/dds/service.hpp"
#include "group_validation.hpp"
#include "hand_directory.hpp"
#include "lease_table.hpp"
#include "reply_sink.hpp"
#include "request_handler.hpp"
#include "request_validation.hpp"

namespace dh3::dds {

/// The reply's overall code and message from its members' results: OK, or the
/// first failed hand's code and every failed hand's reason. Hands CANCELLED
/// because another failed are named only when no hand failed otherwise: the
/// cause is the news.
void summarize_group(msg::GroupReply& reply);

class GroupCommands {
 public:
  /// The parts a group uses; each outlives this.
  struct Parts {
    const ServiceOptions& options;
    const Clock& clock;
    const HandDirectory& directory;
    const LeaseTable& leases;
    const Schedulers& schedulers;
    ReplySink& replies;
    /// A group in flight is one of its caller's requests in flight.
    ClientShare& share;
    /// A group is one of its caller's requests a second, in the same bucket
    /// as its single requests.
    ClientRate& rate;
  };
  explicit GroupCommands(Parts parts) : parts_(parts) {}
  GroupCommands(const GroupCommands&) = delete;
  GroupCommands& operator=(const GroupCommands&) = delete;

  /// Answers the group request of `caller` (`stopping`: CANCELLED, nothing sent).
  void handle(msg::GroupRequest& request, const Caller& caller, bool stopping);

 private:
  struct Pending;

  /// Answers a group that failed its checks: nothing was sent to any hand.
  void refuse(msg::GroupReply& reply, const GroupRefusal& refusal);
  void submit(const std::vector<ValidRequest>& members, msg::GroupReply reply, Duration timeout,
              ClientShare::Ticket ticket);
  [[nodiscard]] MemberFacts member_facts(std::uint16_t bus, std::uint8_t can_id,
                                         const Caller& caller, const std::string& client_id) const;

  Parts parts_;
};

}  // namespace dh3::dds
