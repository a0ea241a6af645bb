/* A participant of another DDS vendor (Eclipse Cyclone DDS, C API) built from
 * idl/dh3.idl by Cyclone's own IDL compiler, as docs/contract.md
 * tells other vendors to: it waits for a hand's status, asks the service for
 * the hand's firmware version (READ_REGISTER 0x1301) and waits for the reply.
 * With "lease" it instead takes the hand's control lease under its
 * participant's GUID prefix as client_id, as dh3's own clients do, and leaves
 * the domain once it holds it.
 *
 *   cyclone_client DOMAIN SERVICE CAN_ID SECONDS [lease]
 *
 * Prints what it saw; exit 0 when the reply is OK, 2 no status, 3 the request
 * writer never matched the service, 4 no reply, 5 a reply other than OK. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* 0 while none; otherwise 1 + the reply's code. */
static int reply_code(dds_entity_t reader, uint64_t seq) {
  void* samples[MAX_SAMPLES] = {NULL};
  dds_sample_info_t infos[MAX_SAMPLES];
  int code = 0;
  dds_return_t n = dds_take(reader, samples, infos, MAX_SAMPLES, MAX_SAMPLES);
  for (dds_return_t i = 0; i < n; ++i) {
    const dh3_msg_CommandReply* reply = samples[i];
    if (!infos[i].valid_data) continue;
    if (strcmp(reply->client_id, client_id) != 0 || reply->request_seq != seq) continue;
    printf("reply code %d value %d message '%s'\n", (int)reply->code, (int)reply->value,
           reply->message);
    code = 1 + (int)reply->code;
  }
  if (n > 0) dds_return_loan(reader, samples, n);
  return code;
}

int main(int argc, char** argv) {
  if (argc != 5 && !(argc == 6 && strcmp(argv[5], "lease") == 0)) {
    fprintf(stderr, "usage: cyclone_client DOMAIN SERVICE CAN_ID SECONDS [lease]\n");
    return 1;
  }
  const int lease = argc == 6;
  const dds_domainid_t domain = (dds_domainid_t)atoi(argv[1]);
  const char* service = argv[2];
  const uint16_t can_id = (uint16_t)atoi(argv[3]);
  deadline = dds_time() + DDS_SECS(atoi(argv[4]));

  dds_entity_t participant = dds_create_participant(domain, NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "cannot create a participant: %s\n", dds_strretcode(-participant));
    return 1;
  }
  if (lease) {
    /* The GUID prefix (its first 12 bytes) as 24 lowercase hex digits. */
    dds_guid_t guid;
    if (dds_get_guid(participant, &guid) < 0) return 1;
    for (int i = 0; i < 12; ++i) snprintf(client_id + 2 * i, 3, "%02x", guid.v[i]);
    printf("client_id %s\n", client_id);
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
  if (lease) {
    request.command = dh3_msg_ACQUIRE_LEASE;
    request.value = 600000; /* ms: longer than any test, so only leaving can end it */
  } else {
    request.command = dh3_msg_READ_REGISTER;
    request.register_code = 0x1301;
  }
  if (dds_write(requests, &request) < 0) goto done;

  result = 4;
  while (time_left()) {
    const int code = reply_code(replies, request.request_seq);
    if (code != 0) {
      result = code - 1 == dh3_msg_OK ? 0 : 5;
      break;
    }
    dds_sleepfor(DDS_MSECS(20));
  }
done:
  dds_delete(participant);
  return result;
}
