// canyon's ROS 2 samples decoded without canyon's IDL: the upstream ROS 2 .msg definitions (ROS 2 Humble, from
// @foxglove/rosmsg-msgs-common) parsed by @foxglove/rosmsg drive @foxglove/rosmsg2-serialization's CDR reader over the
// raw payloads canyon_ros2_raw took off the wire. Every decoded sample is checked against the rover's own .pos: the
// stamp (POSIX time of the epoch's GPST), the status mapping, the position and its covariance, the frames.
//
// Usage: node wire_check.mjs DIR     (DIR: fix.bin, odom.bin, diag.bin, rover.pos; exit 0 pass, 1 fail)

import fs from "node:fs";
import path from "node:path";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import { check, failures } from "./check.mjs";
import { frames as framesOf, msgdef } from "./ros2_defs.mjs";

const dir = process.argv[2];
const reader = (type) => new MessageReader(parse(msgdef(type), { ros2: true }));  // "sensor_msgs/msg/NavSatFix"
const frames = (file) => framesOf(path.join(dir, file));

// The rover's .pos: GPST week, tow, lat, lon, h, Q, ns, sdn, sde, sdu, ...
const GPS_POSIX_S = 315964800, LEAP_S = 18, WEEK_S = 604800;
const pos = fs.readFileSync(path.join(dir, "rover.pos"), "utf8").split("\n").filter((l) => l && !l.startsWith("%"))
  .map((l) => {
    const f = l.trim().split(/\s+/).map(Number);
    return { posix: GPS_POSIX_S + f[0] * WEEK_S + f[1] - LEAP_S, lat: f[2], lon: f[3], h: f[4], q: f[5], ns: f[6],
             sdn: f[7], sde: f[8], sdu: f[9] };
  });
const byTime = new Map(pos.map((r) => [Math.round(r.posix * 1000), r]));
const stampOf = (m) => Math.round((m.header.stamp.sec + m.header.stamp.nanosec * 1e-9) * 1000);
const near = (a, b, tol) => Math.abs(a - b) <= tol;

// WGS84 geodetic -> ECEF -> ENU at an origin.
const A = 6378137.0, F = 1 / 298.257223563, E2 = F * (2 - F), RAD = Math.PI / 180;
function ecef(lat, lon, h) {
  const [p, l] = [lat * RAD, lon * RAD];
  const n = A / Math.sqrt(1 - E2 * Math.sin(p) ** 2);
  return [(n + h) * Math.cos(p) * Math.cos(l), (n + h) * Math.cos(p) * Math.sin(l), (n * (1 - E2) + h) * Math.sin(p)];
}
function enu(r, o) {
  const [x, y, z] = ecef(r.lat, r.lon, r.h), [x0, y0, z0] = ecef(o.lat, o.lon, o.h);
  const [dx, dy, dz] = [x - x0, y - y0, z - z0], [p, l] = [o.lat * RAD, o.lon * RAD];
  return [-Math.sin(l) * dx + Math.cos(l) * dy,
          -Math.sin(p) * Math.cos(l) * dx - Math.sin(p) * Math.sin(l) * dy + Math.cos(p) * dz,
          Math.cos(p) * Math.cos(l) * dx + Math.cos(p) * Math.sin(l) * dy + Math.sin(p) * dz];
}
// Variances from the .pos sigmas (4 decimals): within the rounding.
const varianceNear = (v, sd) => near(Math.sqrt(Math.max(v, 0)), sd, 6e-5 + 1e-6 * sd);

// NavSatFix.
const fixReader = reader("sensor_msgs/msg/NavSatFix");
const fixes = frames("fix.bin").map((b) => fixReader.readMessage(b));
check(fixes.length === pos.length, `NavSatFix: ${fixes.length} samples for ${pos.length} epochs`);
let gnss = 0;
for (const m of fixes) {
  const r = byTime.get(stampOf(m));
  if (!check(r !== undefined, `NavSatFix stamp ${m.header.stamp.sec}.${m.header.stamp.nanosec} is an epoch of the .pos`)) break;
  const want = r.q === 1 || r.q === 2 ? 2 : r.q === 5 ? 0 : -1;
  if (!check(m.status.status === want, `NavSatFix status ${m.status.status} for Q ${r.q} (want ${want})`)) break;
  check(m.header.frame_id === "gnss" && m.status.service === (1 | 2 | 8), "NavSatFix frame_id gnss, service GPS|GLONASS|GALILEO");
  if (want < 0) {
    check(Number.isNaN(m.latitude) && m.position_covariance_type === 0, "NO_FIX without a position");
    continue;
  }
  gnss += 1;
  const ok = near(m.latitude, r.lat, 1e-9) && near(m.longitude, r.lon, 1e-9) && near(m.altitude, r.h, 1e-4) &&
             m.position_covariance_type === 3 && varianceNear(m.position_covariance[0], r.sde) &&
             varianceNear(m.position_covariance[4], r.sdn) && varianceNear(m.position_covariance[8], r.sdu);
  if (!check(ok, `NavSatFix at ${r.posix}: ${m.latitude} ${m.longitude} ${m.altitude} cov ${m.position_covariance} ` +
                 `against ${r.lat} ${r.lon} ${r.h} sd ${r.sde} ${r.sdn} ${r.sdu}`)) break;
}

// Odometry: every solved epoch, ENU from the first GNSS fix.
const odomReader = reader("nav_msgs/msg/Odometry");
const odoms = frames("odom.bin").map((b) => odomReader.readMessage(b));
const solved = pos.filter((r) => r.q !== 0);
const origin = pos.find((r) => r.q === 1 || r.q === 2 || r.q === 5);
const afterOrigin = solved.filter((r) => r.posix >= origin.posix);
check(odoms.length === afterOrigin.length, `Odometry: ${odoms.length} samples for ${afterOrigin.length} solved epochs from the first fix`);
for (const m of odoms) {
  const r = byTime.get(stampOf(m));
  if (!check(r !== undefined, "Odometry stamp is an epoch of the .pos")) break;
  const [e, n, u] = enu(r, origin);
  const p = m.pose.pose.position, c = m.pose.covariance;
  const ok = m.header.frame_id === "map" && m.child_frame_id === "gnss_antenna" && near(p.x, e, 1e-3) &&
             near(p.y, n, 1e-3) && near(p.z, u, 1e-3) && m.pose.pose.orientation.w === 1 &&
             varianceNear(c[0], r.sde) && varianceNear(c[7], r.sdn) && varianceNear(c[14], r.sdu) && c[21] === 1e9 &&
             m.twist.covariance[0] === 1e9;
  if (!check(ok, `Odometry at ${r.posix}: ${p.x} ${p.y} ${p.z} against ${e} ${n} ${u}`)) break;
}

// DiagnosticArray: every epoch, canyon's exact status beside the fix.
const diagReader = reader("diagnostic_msgs/msg/DiagnosticArray");
const diags = frames("diag.bin").map((b) => diagReader.readMessage(b));
check(diags.length === pos.length, `DiagnosticArray: ${diags.length} samples for ${pos.length} epochs`);
const names = { 0: ["none"], 1: ["fixed"], 2: ["float", "partial fix"], 5: ["single"], 7: ["fill-in"] };
let partial = 0;
for (const m of diags) {
  const r = byTime.get(stampOf(m));
  if (!check(r !== undefined && m.status.length === 1, "DiagnosticArray stamp is an epoch, one status")) break;
  const s = m.status[0], values = Object.fromEntries(s.values.map((kv) => [kv.key, kv.value]));
  partial += values.status === "partial fix" ? 1 : 0;
  const ok = s.name === "canyon rover: walker" && names[r.q].includes(values.status) && "ambiguity_ms" in values &&
             Number(values.satellites) === r.ns && (s.level === 0 || s.level === 1);
  if (!check(ok, `DiagnosticArray at ${r.posix}: ${JSON.stringify(values)} for Q ${r.q}`)) break;
}
console.log(`decoded ${fixes.length} NavSatFix (${gnss} with a GNSS position), ${odoms.length} Odometry, ` +
            `${diags.length} DiagnosticArray (${partial} partial fixes) against ${pos.length} epochs: ` +
            (failures.length === 0 ? "PASS" : `${failures.length} failures`));
process.exit(failures.length === 0 ? 0 : 1);
