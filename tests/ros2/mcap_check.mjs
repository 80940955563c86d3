// canyon's MCAP recording read without canyon's code: @mcap/core's stream reader (which checks every record of the
// file), then every message decoded with its channel's schema: OMG IDL parsed by @foxglove/omgidl-parser and CDR read
// by @foxglove/omgidl-serialization. The solutions recorded (canyon/solution, rt/canyon/fix) are compared with the
// rover's own .pos, every topic's message count with the epochs.
//
// Usage: node mcap_check.mjs SESSION.mcap ROVER.pos EPOCHS TOPIC...   (exit 0 pass, 1 fail)

import fs from "node:fs";
import { McapStreamReader } from "@mcap/core";
import { decompressHandlers } from "./mcap_zstd.mjs";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import { check, failures } from "./check.mjs";

const [file, posFile, epochsText, ...topics] = process.argv.slice(2);
const epochs = Number(epochsText);

const reader = new McapStreamReader({ validateCrcs: true, decompressHandlers });
reader.append(fs.readFileSync(file));
const schemas = new Map(), channels = new Map(), decoded = new Map(), kinds = new Map();
for (let record; (record = reader.nextRecord()) !== undefined;) {
  kinds.set(record.type, (kinds.get(record.type) ?? 0) + 1);
  if (record.type === "Schema") {
    check(record.encoding === "omgidl", `schema ${record.name} is OMG IDL (${record.encoding})`);
    schemas.set(record.id, new MessageReader(record.name, parseIDL(new TextDecoder().decode(record.data))));
  } else if (record.type === "Channel") {
    check(record.messageEncoding === "cdr", `channel ${record.topic} is CDR`);
    channels.set(record.id, record);
    if (!decoded.has(record.topic)) decoded.set(record.topic, []);  // the summary repeats the channels
  } else if (record.type === "Message") {
    const channel = channels.get(record.channelId);
    decoded.get(channel.topic).push({ log: record.logTime, message: schemas.get(channel.schemaId).readMessage(record.data) });
  }
}
check(reader.done(), "the stream reader reached the end of a complete file (footer, magic)");
check(kinds.get("Statistics") === 1 && kinds.get("Footer") === 1 && kinds.get("DataEnd") === 1,
      `a DataEnd, a Statistics and a Footer record: ${JSON.stringify(Object.fromEntries(kinds))}`);

for (const topic of topics) {
  const n = decoded.get(topic)?.length ?? 0;
  const want = topic === "rt/canyon/odometry" ? n : epochs;  // Odometry from the first fix on
  check(n === want && n > 0, `${topic}: ${n} messages for ${want}`);
}

// The solutions against the rover's .pos.
const GPS_POSIX_S = 315964800, LEAP_S = 18, WEEK_S = 604800;
const pos = fs.readFileSync(posFile, "utf8").split("\n").filter((l) => l && !l.startsWith("%")).map((l) => {
  const f = l.trim().split(/\s+/).map(Number);
  return { week: f[0], tow: f[1], lat: f[2], lon: f[3], h: f[4], q: f[5] };
});
const solutions = decoded.get("canyon/solution") ?? [];
solutions.forEach(({ message: m }, k) => {
  const r = pos[k];
  const q = m.status === 8 ? 2 : m.status;  // a partial fix is a float in .pos
  const ok = r && m.sequence_number === BigInt(k) && m.gps_week === r.week && Math.abs(m.gps_tow_s - r.tow) < 5e-4 &&
             q === r.q && Math.abs(m.lat_deg - r.lat) <= 1e-9 && Math.abs(m.lon_deg - r.lon) <= 1e-9 &&
             Math.abs(m.height_m - r.h) <= 1e-4 && m.rover_id === "walker";
  check(ok, `canyon/solution ${k}: ${m.gps_week} ${m.gps_tow_s} status ${m.status} ${m.lat_deg} ${m.lon_deg} against ${JSON.stringify(r)}`);
});
(decoded.get("rt/canyon/fix") ?? []).forEach(({ message: m }, k) => {
  const r = pos[k];
  const posix = m.header.stamp.sec + m.header.stamp.nanosec * 1e-9;
  const ok = r && Math.abs(posix - (GPS_POSIX_S + r.week * WEEK_S + r.tow - LEAP_S)) < 5e-4 &&
             Math.abs(m.latitude - r.lat) <= 1e-9 && Math.abs(m.longitude - r.lon) <= 1e-9;
  check(ok, `rt/canyon/fix ${k}: ${posix} ${m.latitude} ${m.longitude} against ${JSON.stringify(r)}`);
});
const total = [...decoded.values()].reduce((s, v) => s + v.length, 0);
console.log(`MCAP: ${schemas.size} schemas, ${channels.size} channels, ${total} messages decoded with their OMG IDL ` +
            `schemas; ${solutions.length} solutions equal to the .pos: ` +
            (failures.length === 0 ? "PASS" : `${failures.length} failures`));
process.exit(failures.length === 0 ? 0 : 1);
