/* A participant of Eclipse Cyclone DDS reading rt/joint_states as a ROS 2
 * node on rmw_cyclonedds subscribes: type sensor_msgs::msg::dds_::JointState_
 * (compiled by Cyclone's idlc from the ROS-mirroring IDL), XCDR1, RELIABLE,
 * VOLATILE, KEEP_LAST 10. Prints each message's first joint and its position;
 * exits 0 once a message names the joint given, 2 if none did in time.
 *   cyclone_joint_states DOMAIN JOINT_NAME SECONDS */
#include <dds/dds.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ros2_interfaces.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: %s DOMAIN JOINT_NAME SECONDS\n", argv[0]);
    return 1;
  }
  dds_entity_t participant = dds_create_participant((dds_domainid_t)atoi(argv[1]), NULL, NULL);
  if (participant < 0) return 1;
  dds_entity_t topic = dds_create_topic(participant, &sensor_msgs_msg_dds__JointState__desc,
                                        "rt/joint_states", NULL, NULL);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
  dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos, 1, &xcdr1);
  dds_entity_t reader = dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  if (topic < 0 || reader < 0) return 1;
  const dds_time_t deadline = dds_time() + DDS_SECS(atoi(argv[3]));
  int found = 0;
  while (!found && dds_time() < deadline) {
    void* samples[1] = {NULL};
    dds_sample_info_t info[1];
    int n = dds_take(reader, samples, info, 1, 1);
    if (n <= 0) {
      dds_sleepfor(DDS_MSECS(20));
      continue;
    }
    const sensor_msgs_msg_dds__JointState_* m = samples[0];
    if (info[0].valid_data && m->name._length == 2 && m->position._length == 2) {
      printf("joint %s position %f stamp %d\n", m->name._buffer[0], m->position._buffer[0],
             m->header.stamp.sec);
      found = strcmp(m->name._buffer[0], argv[2]) == 0;
    }
    dds_return_loan(reader, samples, n);
  }
  dds_delete(participant);
  return found ? 0 : 2;
}
