// DDS wiring: the client's participant, its readers and writers, and which
// of them DDS Security refused (a read-only client).

#include "client_endpoints.hpp"

#include "dh3/base/host_name.hpp"
#include "dh3/contract/admin_commands.hpp"
#include "dh3/contract/participant_options.hpp"
#include "dh3/contract/qos.hpp"
#include "dh3/contract/request_address.hpp"

namespace dh3::detail {

namespace {

contract::ParticipantOptions participant_options(const ClientOptions& options) {
  auto participant_options = contract::participant_options_of(options);
  // Lease holders are shown by their participant's name (the service's
  // participant_names.hpp): it says which program on which host.
  participant_options.name = program_at_host(options.participant_name);
  // A client needs services, not the other clients: N clients that find each
  // other cost on the order of N^3 discovery messages.
  participant_options.is_client = true;
  return participant_options;
}

fdds::StatusMask data_and_matches() {
  auto mask = fdds::StatusMask::data_available();
  mask << fdds::StatusMask::subscription_matched();
  return mask;
}

}  // namespace

fdds::Publisher& ClientEndpoints::publisher_for(const std::optional<contract::Follow>& follow) {
  return follow ? participant_->cell_publisher(follow->service) : participant_->publisher();
}

fdds::Subscriber& ClientEndpoints::subscriber_for(const std::optional<contract::Follow>& follow) {
  return follow ? participant_->cell_subscriber(follow->service) : participant_->subscriber();
}

void ClientEndpoints::create_command_endpoints(const EndpointCreator& creator,
                                               const std::string& client_id,
                                               const std::optional<contract::Follow>& follow) {
  using contract::TopicRole;
  const contract::Topics& topics = participant_->topics();
  // The command endpoints first, each right after the other: the service
  // answers on the reply topic as soon as a request arrives, so our reply
  // reader's announcement should trail the request writer's as little as
  // possible (a reply written before the service knows our reader is lost).
  // A follower commands its cell only: its endpoints are in the cell's
  // partition, so the other cells' reply writers do not even match it.
  request_writer_ =
      creator.create_writer(ClientEndpoint::request_writer, publisher_for(follow), topics.request,
                            contract::writer_qos(TopicRole::request), &request_listener_,
                            fdds::StatusMask::publication_matched());
  // Refused by access control unless the identity is an admin's: then only
  // administrative commands end DENIED.
  admin_request_writer_ =
      creator.create_writer(ClientEndpoint::admin_request_writer, publisher_for(follow),
                            topics.admin_request, contract::writer_qos(TopicRole::request),
                            &admin_request_listener_, fdds::StatusMask::publication_matched());
  // Only our replies: the service's writer sends each client its own (see
  // dh3/contract/reply_filter.hpp), instead of every client taking every reply.
  // Should Fast DDS refuse the filtered topic, the plain one still works:
  // on_reply() keeps only our client_id.
  fdds::TopicDescription* own_replies =
      contract::create_own_replies_topic(participant_->participant(), topics.reply, client_id);
  if (own_replies == nullptr) own_replies = topics.reply;
  // VOLATILE, though the service's reply writer is TRANSIENT_LOCAL (for other
  // vendors' clients, which the contract tells to read it so): a new client
  // is then sent none of the replies the writer keeps from before it joined
  // (Fast DDS filters a writer's history only for the readers matched when
  // each reply was written, so they would all come, to be dropped here).
  // Nothing of its own is lost: the service holds a reply to a dh3 client
  // until the client's reply reader has matched its writer (ReplyGate).
  auto reply_qos = contract::reader_qos(TopicRole::reply);
  reply_qos.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
  reply_reader_ =
      creator.create_reader(ClientEndpoint::reply_reader, subscriber_for(follow), own_replies,
                            reply_qos, &reader_listener_, data_and_matches());
}

void ClientEndpoints::create_group_endpoints(const EndpointCreator& creator,
                                             const std::optional<contract::Follow>& follow) {
  using contract::TopicRole;
  const contract::Topics& topics = participant_->topics();
  group_request_writer_ =
      creator.create_writer(ClientEndpoint::group_request_writer, publisher_for(follow),
                            topics.group_request, contract::writer_qos(TopicRole::request),
                            &group_request_listener_, fdds::StatusMask::publication_matched());
  // The plain topic: group replies are few, and on_group_reply() keeps only
  // this client's. VOLATILE for the reason the reply reader is: the service
  // holds a group reply until this reader has matched (its group ReplyGate).
  auto group_reply_qos = contract::reader_qos(TopicRole::reply);
  group_reply_qos.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
  group_reply_reader_ = creator.create_reader(
      ClientEndpoint::group_reply_reader, subscriber_for(follow), topics.group_reply,
      group_reply_qos, &reader_listener_, data_and_matches());
}

void ClientEndpoints::create_watch_endpoints(const EndpointCreator& creator,
                                             const std::optional<contract::Follow>& follow) {
  using contract::TopicRole;
  const contract::Topics& topics = participant_->topics();
  // A follower reads in its cell's partition, so the other cells' writers do
  // not even match it (dh3/contract/cell_partition.hpp), and each topic through the
  // follow filter, which the services' writers evaluate for it
  // (dh3/contract/follow_filter.hpp; it also picks one bus). Should Fast DDS refuse a
  // filtered topic, the plain one still works: ClientCore keeps only what it
  // follows.
  auto& subscriber = subscriber_for(follow);
  const auto data = fdds::StatusMask::data_available();
  const auto view = [&](fdds::Topic* topic, bool by_bus) -> fdds::TopicDescription* {
    if (!follow) return topic;
    fdds::TopicDescription* filtered =
        contract::create_follow_topic(participant_->participant(), topic, *follow, by_bus);
    return filtered != nullptr ? filtered : topic;
  };
  status_reader_ =
      creator.create_reader(ClientEndpoint::status_reader, subscriber, view(topics.status, true),
                            contract::reader_qos(TopicRole::hand_status), &reader_listener_, data);
  event_reader_ = creator.create_reader(
      ClientEndpoint::event_reader, subscriber, view(topics.event, true),
      contract::reader_qos(TopicRole::hand_event), &reader_listener_, data_and_matches());
  // Only if statuses and events are readable (set_up_dds() fails otherwise).
  if (status_reader_ == nullptr || event_reader_ == nullptr) return;
  info_reader_ =
      creator.create_reader(ClientEndpoint::info_reader, subscriber, view(topics.info, false),
                            contract::reader_qos(TopicRole::service_info), &reader_listener_, data);
  // Who owns each name, and a death within the owner lease (docs/failover.md).
  // Without it (permissions that predate it) a death is seen when the
  // participant lease ends, and the first claimant of a name is believed.
  owner_reader_ = creator.create_reader(
      ClientEndpoint::owner_reader, subscriber, topics.owner,
      contract::reader_qos(TopicRole::service_owner), &reader_listener_,
      data_and_matches() << fdds::StatusMask::liveliness_changed());
}

Result<void, std::string> ClientEndpoints::create_participant(const ClientOptions& options) {
  // The library writes no log, so the report is not shown; what an XML profile
  // overrides is said where ClientOptions is documented.
  contract::SetupReport report;
  return participant_.join(participant_options(options), report);
}

Result<void, std::string> ClientEndpoints::create_endpoints(
    const EndpointCreator& creator, const std::string& client_id,
    const std::optional<contract::Follow>& follow) {
  // With access control, a writer or reader the permissions do not grant
  // fails to be created: for the command endpoints that makes a read-only
  // client, not a failure.
  const bool access_control = creator.access_control(*participant_);
  create_command_endpoints(creator, client_id, follow);
  create_group_endpoints(creator, follow);
  // Every identity must read statuses and events; a refused command endpoint
  // above is a read-only client.
  create_watch_endpoints(creator, follow);
  if (status_reader_ == nullptr || event_reader_ == nullptr) {
    return fail(access_control ? "DDS Security: this identity may not read hand statuses and events"
                               : "cannot create the dh3 readers");
  }
  if (!(can_command() && has_info_reader()) && !access_control) {
    return fail("cannot create the dh3 readers and writers");
  }
  return {};
}

std::string ClientEndpoints::denied_message(const ClientOptions& options) {
  std::string message = "not permitted to publish command requests";
  if (!options.security_dir.empty()) {
    message += " (DDS Security identity '" + options.security_identity + "')";
  } else {
    message += " (DDS Security permissions of this participant)";
  }
  return message;
}

std::string ClientEndpoints::admin_denied_message(const ClientOptions& options) {
  std::string message =
      "not permitted to publish administrative requests (" + std::string(topics::ADMIN_REQUEST);
  if (!options.security_dir.empty()) {
    message += "; DDS Security identity '" + options.security_identity + "' is no admin)";
  } else {
    message += "; DDS Security permissions of this participant)";
  }
  return message;
}

bool ClientEndpoints::write(const msg::CommandRequest& request, const std::string& to) {
  // DataWriter::write takes a non-const sample.
  msg::CommandRequest sample = request;
  auto address = contract::addressed_to(to);
  if (contract::is_administrative(request.command())) {
    return admin_request_writer_->write(&sample, address);
  }
  return request_writer_->write(&sample, address);
}

bool ClientEndpoints::write(msg::GroupRequest& request, const std::string& to) {
  auto address = contract::addressed_to(to);
  return group_request_writer_->write(&request, address);
}

bool ClientEndpoints::requests_acknowledged() const {
  return request_writer_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(0, 0)) ==
         eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK;
}

std::uint64_t ClientEndpoints::replies_filtered() const {
  if (!participant_.joined()) return 0;
  return participant_->reply_filter_counts().rejected.load(std::memory_order_relaxed);
}

std::uint64_t ClientEndpoints::follow_filtered() const {
  if (!participant_.joined()) return 0;
  return participant_->follow_filter_counts().rejected.load(std::memory_order_relaxed);
}

}  // namespace dh3::detail
