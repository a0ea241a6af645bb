/* A participant of another DDS vendor (Eclipse Cyclone DDS, C API) built from
 * idl/dh3.idl by Cyclone's own IDL compiler, as docs/contract.md
 * tells other vendors to: it waits for a hand's status, asks the service for
 * the hand's firmware version (READ_REGISTER 0x1301) and waits for the reply.
 * With "lease" it instead takes the hand's control lease under its
 * participant's GUID prefix as client_id, as dh3's own clients do, and leaves
 * the domain once it holds it. With "hold" it takes the lease, initializes the
 * hand, moves it to 20 and stays until SECONDS end. With "forge ID" it plays
 * an attacker who learnt the holder's client_id ID: MOVE 30 under that
 * client_id must be answered DENIED, and a read sent after it must show the
 * hand's target unchanged.
 *
 *   cyclone_client DOMAIN SERVICE CAN_ID SECONDS [lease | hold | forge ID]
 *
 * Its participant is named "cyclone_client@<host>", as dh3's clients name
 * theirs. Prints what it saw; exit 0 when the reply is OK (forge: DENIED and
 * the hand not moved), 2 no status, 3 the request writer never matched the
 * service, 4 no reply, 5 a reply other than OK (forge: other than DENIED),
 * 6 (forge) the hand's target moved. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dds/dds.h"
#include "dh3.h"

#define MAX_SAMPLES 16

static char client_id[32] = "cyclone-client";

static dds_time_t deadline;

static int time_left(void) { return dds_time() < deadline; }

static dds_entity_t reader_for(dds_entity_t participant, const dds_topic_descriptor_t* type,
                               const char* name, int durable, int32_t depth) {
  dds_entity_t topic = dds_create_topic(participant, type, name, NULL, NULL);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, durable ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
  dds_entity_t reader = dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  return reader;
}

/* The status of SERVICE/bus0/CAN_ID with online set, as the contract publishes it. */
static int saw_online_status(dds_entity_t reader, const char* service, uint16_t can_id) {
  void* samples[MAX_SAMPLES] = {NULL};
  dds_sample_info_t infos[MAX_SAMPLES];
  int found = 0;
  dds_return_t n = dds_take(reader, samples, infos, MAX_SAMPLES, MAX_SAMPLES);
  for (dds_return_t i = 0; i < n; ++i) {
    const dh3_msg_HandStatus* status = samples[i];
    if (!infos[i].valid_data) continue;
    if (strcmp(status->service, service) == 0 && strcmp(status->bus, "bus0") == 0 &&
        status->can_id == can_id && status->online) {
      printf("status %s/%s/%u online, firmware %s\n", status->service, status->bus,
             (unsigned)status->can_id, status->firmware_version_text);
      found = 1;
    }
  }
  if (n > 0) dds_return_loan(reader, samples, n);
  return found;
}

/* 0 while none; otherwise 1 + the reply's code. The reply must carry `id`. */
static int reply_code(dds_entity_t reader, const char* id, uint64_t seq, int32_t* target) {
  void* samples[MAX_SAMPLES] = {NULL};
  dds_sample_info_t infos[MAX_SAMPLES];
  int code = 0;
  dds_return_t n = dds_take(reader, samples, infos, MAX_SAMPLES, MAX_SAMPLES);
  for (dds_return_t i = 0; i < n; ++i) {
    const dh3_msg_CommandReply* reply = samples[i];
    if (!infos[i].valid_data) continue;
    if (strcmp(reply->client_id, id) != 0 || reply->request_seq != seq) continue;
    printf("reply code %d value %d message '%s'\n", (int)reply->code, (int)reply->value,
           reply->message);
    printf("lease_holder '%s' target_position %d\n", reply->status.lease_holder,
           (int)reply->status.target_position);
    if (target != NULL) *target = reply->status.target_position;
    code = 1 + (int)reply->code;
  }
  if (n > 0) dds_return_loan(reader, samples, n);
  return code;
}

/* Sends the request and waits for its reply: 1 + its code, 0 if none came in time. */
static int call(dds_entity_t writer, dds_entity_t replies, dh3_msg_CommandRequest* request,
                int32_t* target) {
  if (dds_write(writer, request) < 0) return 0;
  while (time_left()) {
    const int code = reply_code(replies, request->client_id, request->request_seq, target);
    if (code != 0) return code;
    dds_sleepfor(DDS_MSECS(20));
  }
  return 0;
}

/* hold: the lease, then INITIALIZE and MOVE 20 as its holder; 0 when all were OK. */
static int hold(dds_entity_t writer, dds_entity_t replies, dh3_msg_CommandRequest* request) {
  static const dh3_msg_CommandType commands[] = {dh3_msg_ACQUIRE_LEASE, dh3_msg_INITIALIZE,
                                                 dh3_msg_MOVE};
  static const int32_t values[] = {600000, 0, 20};
  for (int i = 0; i < 3; ++i) {
    request->request_seq = (uint64_t)i + 1;
    request->command = commands[i];
    request->value = values[i];
    const int code = call(writer, replies, request, NULL);
    if (code == 0) return 4;
    if (code - 1 != dh3_msg_OK) return 5;
  }
  printf("holding\n");
  fflush(stdout);
  while (time_left()) dds_sleepfor(DDS_MSECS(100));
  return 0;
}

/* forge: MOVE 30 under the holder's client_id `id` must be DENIED; a read sent
 * after it (same hand, same queue) must show the target still not 30. */
static int forge(dds_entity_t writer, dds_entity_t replies, dh3_msg_CommandRequest* request,
                 char* id) {
  char* own = request->client_id;
  request->client_id = id;
  request->request_seq = 1000; /* not one of the holder's own, whose replies we read too */
  request->command = dh3_msg_MOVE;
  request->value = 30;
  int code = call(writer, replies, request, NULL);
  request->client_id = own;
  if (code == 0) return 4;
  if (code - 1 != dh3_msg_DENIED) return 5;
  int32_t target = -1;
  request->request_seq = 1001;
  request->command = dh3_msg_READ_REGISTER;
  request->value = 0;
  request->register_code = 0x0602;
  code = call(writer, replies, request, &target);
  if (code == 0) return 4;
  if (code - 1 != dh3_msg_OK) return 5;
  return target == 30 ? 6 : 0;
}

int main(int argc, char** argv) {
  const int lease = argc == 6 && strcmp(argv[5], "lease") == 0;
  const int holding = argc == 6 && strcmp(argv[5], "hold") == 0;
  const int forging = argc == 7 && strcmp(argv[5], "forge") == 0;
  if (argc != 5 && !lease && !holding && !forging) {
    fprintf(stderr, "usage: cyclone_client DOMAIN SERVICE CAN_ID SECONDS [lease | hold | forge ID]\n");
    return 1;
  }
  const dds_domainid_t domain = (dds_domainid_t)atoi(argv[1]);
  const char* service = argv[2];
  const uint16_t can_id = (uint16_t)atoi(argv[3]);
  deadline = dds_time() + DDS_SECS(atoi(argv[4]));

  char name[300] = "cyclone_client@";
  gethostname(name + strlen(name), sizeof name - strlen(name) - 1);
  dds_qos_t* participant_qos = dds_create_qos();
  dds_qset_entity_name(participant_qos, name);
  dds_entity_t participant = dds_create_participant(domain, participant_qos, NULL);
  dds_delete_qos(participant_qos);
  if (participant < 0) {
    fprintf(stderr, "cannot create a participant: %s\n", dds_strretcode(-participant));
    return 1;
  }
  if (lease || holding) {
    /* The GUID prefix (its first 12 bytes) as 24 lowercase hex digits. */
    dds_guid_t guid;
    if (dds_get_guid(participant, &guid) < 0) return 1;
    for (int i = 0; i < 12; ++i) snprintf(client_id + 2 * i, 3, "%02x", guid.v[i]);
    printf("client_id %s\n", client_id);
    fflush(stdout);
  } else if (forging) {
    strcpy(client_id, "cyclone-forger");
  }
  dds_entity_t status = reader_for(participant, &dh3_msg_HandStatus_desc, dh3_topics_HAND_STATUS,
                                   1, 1);
  dds_entity_t replies = reader_for(participant, &dh3_msg_CommandReply_desc,
                                    dh3_topics_COMMAND_REPLY, 1, 64);
  dds_entity_t request_topic = dds_create_topic(participant, &dh3_msg_CommandRequest_desc,
                                                dh3_topics_COMMAND_REQUEST, NULL, NULL);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 64);
  dds_entity_t requests = dds_create_writer(participant, request_topic, qos, NULL);
  dds_delete_qos(qos);
  if (status < 0 || replies < 0 || requests < 0) {
    fprintf(stderr, "cannot create the readers and the writer\n");
    return 1;
  }

  int result = 2;
  while (time_left() && !saw_online_status(status, service, can_id)) dds_sleepfor(DDS_MSECS(20));
  if (!time_left()) goto done;

  result = 3;
  dds_publication_matched_status_t matched = {0};
  while (time_left()) {
    dds_get_publication_matched_status(requests, &matched);
    if (matched.current_count > 0) break;
    dds_sleepfor(DDS_MSECS(20));
  }
  if (matched.current_count == 0) goto done;
  printf("request writer matched\n");

  dh3_msg_CommandRequest request;
  memset(&request, 0, sizeof request);
  request.client_id = client_id;
  request.request_seq = 1;
  request.hand.service = (char*)service;
  request.hand.bus = "bus0";
  request.hand.can_id = can_id;
  if (holding) {
    result = hold(requests, replies, &request);
    goto done;
  }
  if (forging) {
    result = forge(requests, replies, &request, argv[6]);
    goto done;
  }
  if (lease) {
    request.command = dh3_msg_ACQUIRE_LEASE;
    request.value = 600000; /* ms: longer than any test, so only leaving can end it */
  } else {
    request.command = dh3_msg_READ_REGISTER;
    request.register_code = 0x1301;
  }
  result = 4;
  const int code = call(requests, replies, &request, NULL);
  if (code != 0) result = code - 1 == dh3_msg_OK ? 0 : 5;
done:
  dds_delete(participant);
  return result;
}
