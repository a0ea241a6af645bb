#pragma once
// How the client's readers and writers are created: the seam where a test
// stands in for DDS Security's access control (tests/unit/client/refusing_endpoints.hpp).
//
// Stateless; const calls, made by ClientEndpoints while ClientCore's
// constructor sets the client up.

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>

#include "dh3/contract/participant_setup.hpp"

namespace dh3::detail {

namespace fdds = eprosima::fastdds::dds;

/// The client's readers and writers, as EndpointCreator is asked for them.
enum class ClientEndpoint {
  request_writer,
  reply_reader,
  status_reader,
  event_reader,
  info_reader,
  group_request_writer,
  group_reply_reader,
  owner_reader,
  admin_request_writer
};

/// Creates the client's readers and writers. DDS Security's access control
/// refuses an endpoint by failing its creation (nullptr): a refused command
/// endpoint makes a read-only client, not a failure. Tests derive from it to
/// be refused without credentials (tests/unit/client/refusing_endpoints.hpp).
class EndpointCreator {
 public:
  EndpointCreator() = default;
  virtual ~EndpointCreator() = default;
  EndpointCreator(const EndpointCreator&) = delete;
  EndpointCreator& operator=(const EndpointCreator&) = delete;

  /// Whether a refused endpoint may be access control's doing.
  [[nodiscard]] virtual bool access_control(const contract::Participant& participant) const {
    return participant.access_control();
  }
  [[nodiscard]] virtual fdds::DataWriter* create_writer(ClientEndpoint /*which*/,
                                                        fdds::Publisher& publisher,
                                                        fdds::Topic* topic,
                                                        const fdds::DataWriterQos& qos,
                                                        fdds::DataWriterListener* listener,
                                                        const fdds::StatusMask& mask) const {
    return publisher.create_datawriter(topic, qos, listener, mask);
  }
  [[nodiscard]] virtual fdds::DataReader* create_reader(ClientEndpoint /*which*/,
                                                        fdds::Subscriber& subscriber,
                                                        fdds::TopicDescription* topic,
                                                        const fdds::DataReaderQos& qos,
                                                        fdds::DataReaderListener* listener,
                                                        const fdds::StatusMask& mask) const {
    return subscriber.create_datareader(topic, qos, listener, mask);
  }
};

}  // namespace dh3::detail
