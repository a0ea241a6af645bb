// Encodes the messages ros2_golden prints with an independent ROS 2 encoder,
// npm's @foxglove/rosmsg2-serialization, from ROS 2's own message definitions
// (@foxglove/rosmsg-msgs-common for Humble and Jazzy; control_msgs, std_srvs,
// rmw_dds_common, the services' request and response and the types ROS
// derives from an action, written here from their .msg, .srv and .action
// files), and compares byte for byte, for Humble and Jazzy or, for a line
// ending in a distribution, for that one. Also checks that every DDS type
// name is the one ROS 2's middlewares use.
//   node check_golden.js < ros2_golden-output
"use strict";
const { MessageWriter } = require("@foxglove/rosmsg2-serialization");
const common = require("@foxglove/rosmsg-msgs-common");

// control_msgs (identical in Humble 4.8 and Jazzy 5.8) and what rosidl
// derives from GripperCommand.action, ParallelGripperCommand.action,
// action_msgs/srv/CancelGoal.srv, std_srvs/srv/Trigger.srv and
// rcl_interfaces/srv/SetParameters.srv (identical in Humble and Jazzy).
const RESULT = "float64 position\nfloat64 effort\nbool stalled\nbool reached_goal";
const PARALLEL = "control_msgs/ParallelGripperCommand";
const written = {
  [`${PARALLEL}_Goal`]: "sensor_msgs/JointState command",
  [`${PARALLEL}_Result`]: "sensor_msgs/JointState state\nbool stalled\nbool reached_goal",
  [`${PARALLEL}_Feedback`]: "sensor_msgs/JointState state",
  [`${PARALLEL}_SendGoal_Request`]: `unique_identifier_msgs/UUID goal_id\n${PARALLEL}_Goal goal`,
  [`${PARALLEL}_SendGoal_Response`]: "bool accepted\nbuiltin_interfaces/Time stamp",
  [`${PARALLEL}_GetResult_Request`]: "unique_identifier_msgs/UUID goal_id",
  [`${PARALLEL}_GetResult_Response`]: `int8 status\n${PARALLEL}_Result result`,
  [`${PARALLEL}_FeedbackMessage`]:
    `unique_identifier_msgs/UUID goal_id\n${PARALLEL}_Feedback feedback`,
  // Field-less: the encoder itself adds ROS 2's one-byte member.
  "std_srvs/Trigger_Request": "",
  "std_srvs/Trigger_Response": "bool success\nstring message",
  "rcl_interfaces/SetParameters_Request": "rcl_interfaces/Parameter[] parameters",
  "rcl_interfaces/SetParameters_Response": "rcl_interfaces/SetParametersResult[] results",
  // rmw_dds_common/msg (string<=256 is a string on the wire).
  "rmw_dds_common/NodeEntitiesInfo":
    "string node_namespace\nstring node_name\nrmw_dds_common/Gid[] reader_gid_seq\n" +
    "rmw_dds_common/Gid[] writer_gid_seq",
  "rmw_dds_common/ParticipantEntitiesInfo":
    "rmw_dds_common/Gid gid\nrmw_dds_common/NodeEntitiesInfo[] node_entities_info_seq",
  "control_msgs/GripperCommand": "float64 position\nfloat64 max_effort",
  "control_msgs/GripperCommand_Goal": "control_msgs/GripperCommand command",
  "control_msgs/GripperCommand_Result": RESULT,
  "control_msgs/GripperCommand_Feedback": RESULT,
  "control_msgs/GripperCommand_SendGoal_Request":
    "unique_identifier_msgs/UUID goal_id\ncontrol_msgs/GripperCommand_Goal goal",
  "control_msgs/GripperCommand_SendGoal_Response": "bool accepted\nbuiltin_interfaces/Time stamp",
  "control_msgs/GripperCommand_GetResult_Request": "unique_identifier_msgs/UUID goal_id",
  "control_msgs/GripperCommand_GetResult_Response":
    "int8 status\ncontrol_msgs/GripperCommand_Result result",
  "control_msgs/GripperCommand_FeedbackMessage":
    "unique_identifier_msgs/UUID goal_id\ncontrol_msgs/GripperCommand_Feedback feedback",
  "action_msgs/CancelGoal_Request": "action_msgs/GoalInfo goal_info",
  "action_msgs/CancelGoal_Response": "int8 return_code\naction_msgs/GoalInfo[] goals_canceling",
};

// rmw_dds_common/msg/Gid.msg: "char[24] data" in Humble, "char[16] data" in
// Jazzy (ROS 2's char is a uint8).
const gid = { ros2humble: "uint8[24] data", ros2jazzy: "uint8[16] data" };

// "pkg/Type name", "Type[] name" or "Type[N] name" lines as
// @foxglove/message-definition fields.
function fields(text) {
  if (text === "") return [];
  return text.split("\n").map((line) => {
    const [declared, name] = line.split(" ");
    const array = /^(.*)\[(\d*)\]$/.exec(declared);
    const type = array ? array[1] : declared;
    const field = { name, type, isArray: Boolean(array), isComplex: type.includes("/") };
    if (array && array[2] !== "") field.arrayLength = Number(array[2]);
    return field;
  });
}

function library(distro) {
  const all = { ...common[distro] };
  const texts = { ...written, "rmw_dds_common/Gid": gid[distro] };
  for (const [name, text] of Object.entries(texts)) all[name] = { name, definitions: fields(text) };
  return all;
}

// The root definition first, then every type it uses.
function definitions(all, root) {
  const out = [];
  const visit = (name) => {
    if (out.some((d) => d.name === name)) return;
    const found = all[name];
    if (!found) throw new Error(`no definition of ${name}`);
    out.push(found);
    for (const field of found.definitions) if (field.isComplex) visit(field.type);
  };
  visit(root);
  return out;
}

const uuid = { uuid: Uint8Array.from([...Array(16).keys()]) };
const bytes = (first, count) => Uint8Array.from({ length: count }, (_, i) => first + i);
// rcl_interfaces/msg/ParameterValue with nothing set.
const parameterValue = {
  type: 0,
  bool_value: false,
  integer_value: 0n,
  double_value: 0,
  string_value: "",
  byte_array_value: new Uint8Array(),
  bool_array_value: [],
  integer_array_value: [],
  double_array_value: [],
  string_array_value: [],
};
const stamp = { sec: 1700000000, nanosec: 123456789 };
const goalInfo = { goal_id: uuid, stamp };
// The hand status ros2_golden converts: dh3/bus0/1 holding an object at
// 40 % open, rotated 50 %, closing force 60 %; the default units (docs/ros2.md):
// 100 % open = 0.095 m, 100 % force = 90 N, rotation 0-100 % = 0-pi/2 rad.
const expected = {
  "sensor_msgs::msg::dds_::JointState_": {
    header: { stamp, frame_id: "" },
    name: ["dh3_bus0_1_finger_joint", "dh3_bus0_1_rotation_joint"],
    position: [0.4 * 0.095, 0.5 * (Math.PI / 2)],
    velocity: [],
    effort: [0.6 * 90, NaN],
  },
  "action_msgs::msg::dds_::GoalStatusArray_": {
    status_list: [{ goal_info: goalInfo, status: 2 }, { goal_info: goalInfo, status: 2 }],
  },
  "action_msgs::srv::dds_::CancelGoal_Request_": { goal_info: goalInfo },
  "action_msgs::srv::dds_::CancelGoal_Response_": { return_code: 0, goals_canceling: [goalInfo] },
  "control_msgs::action::dds_::GripperCommand_SendGoal_Request_": {
    goal_id: uuid,
    goal: { command: { position: 0.02, max_effort: 20 } },
  },
  "control_msgs::action::dds_::GripperCommand_SendGoal_Response_": { accepted: true, stamp },
  "control_msgs::action::dds_::GripperCommand_GetResult_Request_": { goal_id: uuid },
  "control_msgs::action::dds_::GripperCommand_GetResult_Response_": {
    status: 4,
    result: { position: 0.0285, effort: 54, stalled: true, reached_goal: false },
  },
  "control_msgs::action::dds_::GripperCommand_FeedbackMessage_": {
    goal_id: uuid,
    feedback: { position: 0.05, effort: 0, stalled: false, reached_goal: false },
  },
  "control_msgs::action::dds_::ParallelGripperCommand_SendGoal_Request_": {
    goal_id: uuid,
    goal: { command: fingerJoint(0.02, 20) },
  },
  "control_msgs::action::dds_::ParallelGripperCommand_SendGoal_Response_": { accepted: true, stamp },
  "control_msgs::action::dds_::ParallelGripperCommand_GetResult_Request_": { goal_id: uuid },
  "control_msgs::action::dds_::ParallelGripperCommand_GetResult_Response_": {
    status: 4,
    result: { state: fingerJoint(0.0285, 54), stalled: true, reached_goal: false },
  },
  "control_msgs::action::dds_::ParallelGripperCommand_FeedbackMessage_": {
    goal_id: uuid,
    feedback: { state: fingerJoint(0.05, 0) },
  },
  "std_srvs::srv::dds_::Trigger_Request_": {},
  "std_srvs::srv::dds_::Trigger_Response_": { success: true, message: "initialized" },
  "rcl_interfaces::srv::dds_::SetParameters_Request_": {
    parameters: [
      { name: "closing_force", value: { ...parameterValue, type: 3, double_value: 40.5 } },
      { name: "opening_force", value: { ...parameterValue, type: 2, integer_value: 30n } },
    ],
  },
  "rcl_interfaces::srv::dds_::SetParameters_Response_": {
    results: [
      { successful: true, reason: "" },
      { successful: false, reason: "opening_force 300 is out of range" },
    ],
  },
  // ros_discovery_info from ros2_golden's GUIDs: prefix first..first+11,
  // entity id 00 first 01 kind, zero-padded in Humble.
  "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_@ros2jazzy": discoveryInfo(16),
  "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_@ros2humble": discoveryInfo(24),
};

function fingerJoint(position, effort) {
  return {
    header: { stamp, frame_id: "" },
    name: ["dh3_bus0_1_finger_joint"],
    position: [position],
    velocity: [],
    effort: [effort],
  };
}

function discoveryInfo(size) {
  const guid = (first, kind) => {
    const data = new Uint8Array(size);
    data.set(bytes(first, 12));
    data.set([0, first, 0x01, kind], 12);
    return { data };
  };
  return {
    gid: guid(1, 0xc1),
    node_entities_info_seq: [
      {
        node_namespace: "/cell",
        node_name: "dh3_ros2",
        reader_gid_seq: [guid(2, 0x04)],
        writer_gid_seq: [guid(3, 0x03), guid(4, 0x03)],
      },
    ],
  };
}

// "pkg::msg::dds_::Name_" -> "pkg/Name", the key of the definitions.
function rosName(ddsName) {
  const match = /^(\w+)::(msg|srv|action)::dds_::(\w+)_$/.exec(ddsName);
  return match ? `${match[1]}/${match[3]}` : null;
}

const lines = require("fs").readFileSync(0, "utf8").trim().split("\n");
let failures = 0;
const seen = new Set();
for (const line of lines) {
  const [ddsName, hex, only] = line.split(" ");
  const key = only ? `${ddsName}@${only}` : ddsName;
  seen.add(key);
  if (!(key in expected)) {
    console.log(`FAIL ${key}: not a type name ROS 2 uses for these messages`);
    failures++;
    continue;
  }
  for (const distro of only ? [only] : ["ros2humble", "ros2jazzy"]) {
    const all = library(distro);
    const writer = new MessageWriter(definitions(all, rosName(ddsName)));
    const theirs = Buffer.from(writer.writeMessage(expected[key])).toString("hex");
    if (theirs === hex) {
      console.log(`ok   ${ddsName} (${distro}, ${hex.length / 2} bytes)`);
    } else {
      console.log(`FAIL ${ddsName} (${distro})\n  ours   ${hex}\n  theirs ${theirs}`);
      failures++;
    }
  }
}
for (const name of Object.keys(expected)) {
  if (!seen.has(name)) {
    console.log(`FAIL ${name}: ros2_golden printed no such message`);
    failures++;
  }
}
console.log(failures === 0 ? "all layouts match" : `${failures} mismatches`);
process.exit(failures === 0 ? 0 : 1);
