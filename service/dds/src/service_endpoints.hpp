#pragma once
// The service's endpoints on its participant, but for the owner's
// (owner_beacon.hpp) and the lease writer (lease_publisher.hpp): the writers
// of statuses, events, the service info and replies, and the readers of
// requests. A service makes them as it starts. A standby makes them when it
// starts standing by, with listeners of its own (request_drain.hpp), so that
// every client has matched them long before a takeover: the clients' calls
// go to it as soon as its claim turns active, with no endpoint discovery in
// between (docs/hot-standby.md). The service it becomes gives them its own
// listeners.
//
// Not thread-safe: set-up and tear-down only. The entities belong to the
// participant they were made on and go with it.

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <string>

#include "dh3/base/result.hpp"
#include "dh3/contract/participant_options.hpp"

namespace dh3::contract {
class Participant;
}  // namespace dh3::contract

namespace dh3::dds {

/// Who hears each endpoint; null: nobody.
struct WriterListeners {
  eprosima::fastdds::dds::DataWriterListener* reply = nullptr;
  eprosima::fastdds::dds::DataWriterListener* group_reply = nullptr;
};
struct ReaderListeners {
  eprosima::fastdds::dds::DataReaderListener* request = nullptr;
  eprosima::fastdds::dds::DataReaderListener* admin_request = nullptr;
  eprosima::fastdds::dds::DataReaderListener* group_request = nullptr;
};

struct ServiceEndpoints {
  eprosima::fastdds::dds::DataWriter* status = nullptr;
  eprosima::fastdds::dds::DataWriter* event = nullptr;
  eprosima::fastdds::dds::DataWriter* info = nullptr;
  eprosima::fastdds::dds::DataWriter* reply = nullptr;
  /// Null with the group request reader: group commands are off.
  eprosima::fastdds::dds::DataWriter* group_reply = nullptr;
  eprosima::fastdds::dds::DataReader* request = nullptr;
  /// Null: administrative commands are refused.
  eprosima::fastdds::dds::DataReader* admin_request = nullptr;
  eprosima::fastdds::dds::DataReader* group_request = nullptr;

  /// The status, event, info and reply writers, all of them, or the first
  /// that could not be made, named ("the writer of dh3/hand_status"); then
  /// the group reply writer, left null if refused (DDS Security permissions
  /// that predate it).
  [[nodiscard]] Result<void, std::string> create_writers(contract::Participant& participant,
                                                         const WriterListeners& listeners);
  /// The request reader, or why not (as create_writers); then the admin
  /// request reader and, with the group reply writer, the group request
  /// reader, each left null if refused (as the group reply writer).
  [[nodiscard]] Result<void, std::string> create_readers(contract::Participant& participant,
                                                         const ReaderListeners& listeners);
  /// Endpoints made with other listeners (a standby's) get these.
  void listen(const WriterListeners& listeners);
  void listen(const ReaderListeners& listeners);
};

/// "cannot create WHAT", and what to look at: the DDS Security permissions
/// of the participant's identity or profile, or Fast DDS's log.
[[nodiscard]] std::string cannot_create(const std::string& what,
                                        const contract::ParticipantOptions& options,
                                        const contract::Participant& participant);

}  // namespace dh3::dds
