// ServiceEndpoints: the service's writers and request readers, made and given listeners.

#include "service_endpoints.hpp"

#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>

#include "dh3/contract/participant_setup.hpp"
#include "dh3/contract/qos.hpp"

namespace dh3::dds {
namespace fdds = eprosima::fastdds::dds;
using contract::TopicRole;

namespace {

fdds::StatusMask writer_mask(const fdds::DataWriterListener* listener) {
  return listener ? fdds::StatusMask::publication_matched() : fdds::StatusMask::none();
}

fdds::StatusMask request_mask() {
  return fdds::StatusMask::data_available() << fdds::StatusMask::subscription_matched();
}

/// KEEP_ALL on the service's side (history is not part of matching): a
/// burst of requests from many clients is held back by reliable flow control
/// instead of overwriting requests not yet taken, which would then never be
/// answered.
fdds::DataReaderQos request_qos() {
  auto qos = contract::reader_qos(TopicRole::request);
  qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  return qos;
}

}  // namespace

Result<void, std::string> ServiceEndpoints::create_writers(contract::Participant& participant,
                                                           const WriterListeners& listeners) {
  const contract::Topics& topics = participant.topics();
  const auto writer = [&participant](fdds::DataWriter*& out, fdds::Topic* topic, TopicRole role,
                                     fdds::DataWriterListener* listener =
                                         nullptr) -> Result<void, std::string> {
    out = participant.publisher().create_datawriter(topic, contract::writer_qos(role), listener,
                                                    writer_mask(listener));
    if (out == nullptr) return fail("the writer of " + topic->get_name());
    return {};
  };
  auto created = writer(status, topics.status, TopicRole::hand_status);
  if (created) created = writer(event, topics.event, TopicRole::hand_event);
  if (created) created = writer(info, topics.info, TopicRole::service_info);
  if (created) created = writer(reply, topics.reply, TopicRole::reply, listeners.reply);
  if (!created) return created;
  group_reply = participant.publisher().create_datawriter(
      topics.group_reply, contract::writer_qos(TopicRole::reply), listeners.group_reply,
      writer_mask(listeners.group_reply));
  return {};
}

Result<void, std::string> ServiceEndpoints::create_readers(contract::Participant& participant,
                                                           const ReaderListeners& listeners) {
  const contract::Topics& topics = participant.topics();
  request = participant.subscriber().create_datareader(topics.request, request_qos(),
                                                       listeners.request, request_mask());
  // Without it the service would run and never answer a request.
  if (request == nullptr) return fail("the reader of " + topics.request->get_name());
  admin_request = participant.subscriber().create_datareader(
      topics.admin_request, request_qos(), listeners.admin_request, request_mask());
  if (group_reply != nullptr) {
    group_request = participant.subscriber().create_datareader(topics.group_request, request_qos(),
                                                               listeners.group_request,
                                                               fdds::StatusMask::data_available());
  }
  return {};
}

void ServiceEndpoints::listen(const WriterListeners& listeners) {
  if (reply != nullptr) reply->set_listener(listeners.reply, writer_mask(listeners.reply));
  if (group_reply != nullptr) {
    group_reply->set_listener(listeners.group_reply, writer_mask(listeners.group_reply));
  }
}

void ServiceEndpoints::listen(const ReaderListeners& listeners) {
  if (request != nullptr) request->set_listener(listeners.request, request_mask());
  if (admin_request != nullptr) {
    admin_request->set_listener(listeners.admin_request, request_mask());
  }
  if (group_request != nullptr) {
    group_request->set_listener(listeners.group_request, fdds::StatusMask::data_available());
  }
}

std::string cannot_create(const std::string& what, const contract::ParticipantOptions& options,
                          const contract::Participant& participant) {
  std::string message = "cannot create " + what;
  if (!options.security_dir.empty()) {
    return message + ": the DDS Security permissions of identity '" + options.security_identity +
           "' in '" + options.security_dir + "' must allow it (Fast DDS logs what it refused)";
  }
  if (participant.security_from_profile()) {
    return message + ": the DDS Security permissions the XML profile names must allow it";
  }
  return message + " (Fast DDS logs why)";
}

}  // namespace dh3::dds
