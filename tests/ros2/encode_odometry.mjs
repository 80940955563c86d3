// A VIO run as a ROS 2 nav_msgs/msg/Odometry stream, encoded without canyon's code: @foxglove/rosmsg2-serialization's
// CDR writer driven by the upstream ROS 2 Humble Odometry.msg (@foxglove/rosmsg-msgs-common).
//
// Usage: node encode_odometry.mjs VIO.csv TIMESYNC.csv OUT_DIR [--bad]
// Writes OUT_DIR/vio_gps.csv: the poses of VIO.csv with t_ns on GPST (ns since 1980-01-06, interpolated between the
// time-sync pairs) and without the cross-covariance columns (Odometry has none), the values as text unchanged; and
// OUT_DIR/odometry.bin: one Odometry per pose, framed as canyon_ros2_raw reads it (4-byte little-endian length, the
// CDR payload): header.stamp the same instant on ROS time (POSIX, GPST - 18 s in 2023), frame "odom" -> "imu", the
// pose as in the file, its covariance turned from canyon's (right perturbation, IMU frame) into ROS's (frame odom):
// C_ros = diag(R, R) C diag(R, R)^T. --bad: pose 100 with a NaN covariance entry, pose 200 in frame "world", pose 300
// with child frame "camera" (input the rover must refuse, naming it).

import fs from "node:fs";
import path from "node:path";
import { parse } from "@foxglove/rosmsg";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";
import { msgdef } from "./ros2_defs.mjs";

const [vioPath, syncPath, outDir] = process.argv.slice(2, 5);
const bad = process.argv.includes("--bad");
const writer = new MessageWriter(parse(msgdef("nav_msgs/msg/Odometry"), { ros2: true }));

const rows = (file) => fs.readFileSync(file, "utf8").split("\n").filter((l) => l.trim() !== "");
const sync = rows(syncPath).slice(1).map((l) => l.split(",")).map((f) => ({
  t: BigInt(f[0]), gps: BigInt(f[1]) * 604800n * 1000000000n + BigInt(Math.round(Number(f[2]) * 1e6)) * 1000n,
}));
function toGps(t) {  // device ns -> GPST ns: linear between the neighbouring pairs (beyond the ends: the last slope)
  let k = sync.findIndex((p) => p.t > t);
  if (k <= 0) k = k === 0 ? 1 : sync.length - 1;
  const a = sync[k - 1], b = sync[k];
  const slope = Number(b.gps - a.gps) / Number(b.t - a.t);
  return a.gps + BigInt(Math.round(Number(t - a.t) * slope));
}

const lines = rows(vioPath);
const header = lines[0].split(",").slice(0, 29);
const out = [header.join(",")];
const frames = [];
const GPS_POSIX_S = 315964800n, LEAP_S = 18n, NS = 1000000000n;
lines.slice(1).forEach((line, k) => {
  const f = line.split(",");
  const gps = toGps(BigInt(f[0]));
  out.push([gps.toString(), ...f.slice(1, 29)].join(","));
  const v = f.slice(1, 29).map(Number);
  const [px, py, pz, qx, qy, qz, qw] = v;
  // canyon's upper-triangle covariance of xi = [dp; dtheta] (IMU frame) -> full 6x6.
  const C = Array.from({ length: 6 }, () => new Array(6).fill(0));
  let u = 7;
  for (let r = 0; r < 6; r++) for (let c = r; c < 6; c++) C[r][c] = C[c][r] = v[u++];
  const n = Math.hypot(qx, qy, qz, qw), [x, y, z, w] = [qx / n, qy / n, qz / n, qw / n];
  const R = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
             [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
             [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]];
  const J = (r, c) => (Math.floor(r / 3) === Math.floor(c / 3) ? R[r % 3][c % 3] : 0);
  const cov = new Float64Array(36);
  for (let r = 0; r < 6; r++) {
    for (let c = 0; c < 6; c++) {
      let s = 0;
      for (let i = 0; i < 6; i++) for (let j = 0; j < 6; j++) s += J(r, i) * C[i][j] * J(c, j);
      cov[r * 6 + c] = s;
    }
  }
  let frameId = "odom", child = "imu";
  if (bad && k === 100) cov[7] = NaN;
  if (bad && k === 200) frameId = "world";
  if (bad && k === 300) child = "camera";
  const sec = gps / NS + GPS_POSIX_S - LEAP_S, nanosec = gps % NS;
  const bytes = writer.writeMessage({
    header: { stamp: { sec: Number(sec), nanosec: Number(nanosec) }, frame_id: frameId },
    child_frame_id: child,
    pose: { pose: { position: { x: px, y: py, z: pz }, orientation: { x: qx, y: qy, z: qz, w: qw } }, covariance: cov },
    twist: { twist: { linear: { x: 0, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } }, covariance: new Float64Array(36) },
  });
  const length = Buffer.alloc(4);
  length.writeUInt32LE(bytes.length);
  frames.push(length, Buffer.from(bytes));
});
fs.writeFileSync(path.join(outDir, "vio_gps.csv"), out.join("\n") + "\n");
fs.writeFileSync(path.join(outDir, "odometry.bin"), Buffer.concat(frames));
console.log(`encoded ${lines.length - 1} Odometry samples${bad ? " (3 bad)" : ""}`);
