// The ROS 2 streams of canyon vio (--ros2) and canyon base (outputs.ros2), taken off the wire by canyon_ros2_raw and
// decoded without canyon's IDL (the upstream .msg definitions, @foxglove/rosmsg2-serialization's CDR reader).
//
// Usage: node streams_check.mjs odometry CANYON.bin INDEPENDENT.bin
//          canyon vio's Odometry against the same poses encoded independently (encode_odometry.mjs): same count,
//          stamps, frames and poses exactly, covariances to rounding (1e-9 relative), twist unknown (1e9)
//        node streams_check.mjs rtcm MESSAGES.bin STREAM.rtcm3 FRAME_ID
//          canyon base's rtcm_msgs/msg/Message samples: each one whole RTCM 3 frame (preamble 0xD3, length, CRC
//          place), joined they are STREAM.rtcm3 byte for byte (the frames canyon record took off canyon/rtcm),
//          header.frame_id FRAME_ID, stamps the ROS time of sending (within the last hour, not decreasing)
// Exit 0 pass, 1 fail.

import fs from "node:fs";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import { check, failures } from "./check.mjs";
import { frames, msgdef } from "./ros2_defs.mjs";

// rtcm_msgs/msg/Message.msg of the rtcm_msgs package (not in rosmsg-msgs-common), with the Header it uses.
const RTCM_MESSAGE = "std_msgs/Header header\nuint8[] message\n" +
  "================================================================================\nMSG: std_msgs/Header\n" +
  msgdef("std_msgs/msg/Header");

const [mode, a, b, frameId] = process.argv.slice(2);
const stamp = (m) => BigInt(m.header.stamp.sec) * 1000000000n + BigInt(m.header.stamp.nanosec);
if (mode === "odometry") {
  const reader = new MessageReader(parse(msgdef("nav_msgs/msg/Odometry"), { ros2: true }));
  const canyon = frames(a).map((f) => reader.readMessage(f)), independent = frames(b).map((f) => reader.readMessage(f));
  check(canyon.length === independent.length, `Odometry: ${canyon.length} from canyon vio, ${independent.length} encoded`);
  for (let k = 0; k < Math.min(canyon.length, independent.length); k++) {
    const m = canyon[k], w = independent[k];
    const p = m.pose.pose, q = w.pose.pose;
    const same = stamp(m) === stamp(w) && m.header.frame_id === w.header.frame_id &&
                 m.child_frame_id === w.child_frame_id && p.position.x === q.position.x &&
                 p.position.y === q.position.y && p.position.z === q.position.z;
    // The quaternion as canyon holds it (normalised on reading vio.csv) and as the file has it: to rounding.
    const rotation = ["x", "y", "z", "w"].every((c) => Math.abs(p.orientation[c] - q.orientation[c]) < 1e-12);
    const scale = Math.max(...w.pose.covariance.map(Math.abs));
    const covariance = m.pose.covariance.every((v, i) => Math.abs(v - w.pose.covariance[i]) <= 1e-9 * scale);
    const twist = m.twist.covariance[0] === 1e9 && m.twist.covariance[35] === 1e9;
    if (!check(same && rotation && covariance && twist,
               `Odometry ${k}: canyon ${JSON.stringify(m.header)} ${JSON.stringify(p)} against ` +
               `${JSON.stringify(w.header)} ${JSON.stringify(q)} (covariance ${covariance}, twist ${twist})`)) break;
  }
  console.log(`canyon vio --ros2: ${canyon.length} Odometry decoded, equal to the independently encoded poses: ` +
              (failures.length === 0 ? "PASS" : `${failures.length} failures`));
} else if (mode === "rtcm") {
  const reader = new MessageReader(parse(RTCM_MESSAGE, { ros2: true }));
  const messages = frames(a).map((f) => reader.readMessage(f));
  const stream = fs.readFileSync(b);
  const now = BigInt(Date.now()) * 1000000n;
  let previous = 0n;
  for (const [k, m] of messages.entries()) {
    const bytes = m.message;
    const length = bytes.length >= 3 ? ((bytes[1] & 0x03) << 8) | bytes[2] : -1;
    const ok = bytes[0] === 0xd3 && bytes.length === length + 6 && m.header.frame_id === frameId &&
               stamp(m) >= previous && stamp(m) <= now && now - stamp(m) < 3600n * 1000000000n;
    if (!check(ok, `rtcm_msgs/Message ${k}: ${bytes.length} bytes (RTCM length ${length}), frame ` +
                   `'${m.header.frame_id}', stamp ${m.header.stamp.sec}.${m.header.stamp.nanosec}`)) break;
    previous = stamp(m);
  }
  const joined = Buffer.concat(messages.map((m) => Buffer.from(m.message)));
  check(joined.equals(stream), `the ${messages.length} messages joined (${joined.length} bytes) are not the ` +
                               `${stream.length} bytes of ${b}`);
  console.log(`canyon base outputs.ros2: ${messages.length} rtcm_msgs/msg/Message decoded, one RTCM 3 frame each, ` +
              `joined equal to the DDS stream (${stream.length} bytes): ` +
              (failures.length === 0 ? "PASS" : `${failures.length} failures`));
} else {
  console.log("usage: streams_check.mjs odometry CANYON.bin INDEPENDENT.bin | rtcm MESSAGES.bin STREAM.rtcm3 FRAME_ID");
  process.exit(2);
}
process.exit(failures.length === 0 ? 0 : 1);
