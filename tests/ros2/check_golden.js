// Encodes the messages ros2_golden prints with an independent ROS 2 encoder,
// npm's @foxglove/rosmsg2-serialization, from ROS 2's own message definitions
// (@foxglove/rosmsg-msgs-common for Humble and Jazzy; control_msgs and the
// types ROS derives from an action, written here from their .msg, .srv and
// .action files), and compares byte for byte. Also checks that every DDS type
// name is the one ROS 2's middlewares use.
//   node check_golden.js < ros2_golden-output
"use strict";
const { MessageWriter } = require("@foxglove/rosmsg2-serialization");
const common = require("@foxglove/rosmsg-msgs-common");

// control_msgs (identical in Humble 4.8 and Jazzy 5.8) and what rosidl
// derives from GripperCommand.action and action_msgs/srv/CancelGoal.srv.
const RESULT = "float64 position\nfloat64 effort\nbool stalled\nbool reached_goal";
const written = {
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

// "pkg/Type name" or "Type[] name" lines as @foxglove/message-definition fields.
function fields(text) {
  return text.split("\n").map((line) => {
    const [declared, name] = line.split(" ");
    const isArray = declared.endsWith("[]");
    const type = isArray ? declared.slice(0, -2) : declared;
    return { name, type, isArray, isComplex: type.includes("/") };
  });
}

function library(distro) {
  const all = { ...common[distro] };
  for (const [name, text] of Object.entries(written)) all[name] = { name, definitions: fields(text) };
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
};

// "pkg::msg::dds_::Name_" -> "pkg/Name", the key of the definitions.
function rosName(ddsName) {
  const match = /^(\w+)::(msg|srv|action)::dds_::(\w+)_$/.exec(ddsName);
  return match ? `${match[1]}/${match[3]}` : null;
}

const lines = require("fs").readFileSync(0, "utf8").trim().split("\n");
let failures = 0;
const seen = new Set();
for (const line of lines) {
  const [ddsName, hex] = line.split(" ");
  seen.add(ddsName);
  if (!(ddsName in expected)) {
    console.log(`FAIL ${ddsName}: not a type name ROS 2 uses for these messages`);
    failures++;
    continue;
  }
  for (const distro of ["ros2humble", "ros2jazzy"]) {
    const all = library(distro);
    const writer = new MessageWriter(definitions(all, rosName(ddsName)));
    const theirs = Buffer.from(writer.writeMessage(expected[ddsName])).toString("hex");
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
