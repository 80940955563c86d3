// The ROS 2 test scripts' common reading: the upstream ROS 2 Humble .msg definitions (@foxglove/rosmsg-msgs-common,
// each with the definitions it uses) and the framing canyon_ros2_raw records and publishes (a 4-byte little-endian
// length, then the CDR payload).
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const msgdefs = path.join(path.dirname(require.resolve("@foxglove/rosmsg-msgs-common/package.json")), "msgdefs",
                          "ros2humble");

/// The text of a ROS 2 message definition, "nav_msgs/msg/Odometry".
export function msgdef(type) {
  return fs.readFileSync(path.join(msgdefs, type + ".msg"), "utf8");
}

/// The payloads of a canyon_ros2_raw file.
export function frames(file) {
  const bytes = fs.readFileSync(file);
  const out = [];
  for (let at = 0; at + 4 <= bytes.length;) {
    const n = bytes.readUInt32LE(at);
    out.push(bytes.subarray(at + 4, at + 4 + n));
    at += 4 + n;
  }
  return out;
}
