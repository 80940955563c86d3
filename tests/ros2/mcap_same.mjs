// Two MCAP recordings hold the same messages, topic by topic in order (read with @mcap/core, not canyon's code):
// byte for byte - a session played with canyon play and recorded again equals the original; or --decoded, every
// message decoded with its OMG IDL schema (@foxglove/omgidl-serialization) - a rover's in-process recording
// (dds.record) equals what canyon record took off the wire (the bytes differ only in CDR's alignment padding, which
// Fast DDS leaves uninitialised on the wire).
// Usage: node mcap_same.mjs A.mcap B.mcap [WHAT] [--decoded]   (exit 0 same, 1 different)

import fs from "node:fs";
import { McapStreamReader } from "@mcap/core";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import { decompressHandlers } from "./mcap_zstd.mjs";

const decoded = process.argv.includes("--decoded");
const text = (value) => JSON.stringify(value, (k, v) => (typeof v === "bigint" ? v.toString() : ArrayBuffer.isView(v) ? Array.from(v) : v));

function byTopic(file) {
  const reader = new McapStreamReader({ validateCrcs: true, decompressHandlers });
  reader.append(fs.readFileSync(file));
  const schemas = new Map(), channels = new Map(), topics = new Map();
  for (let r; (r = reader.nextRecord()) !== undefined;) {
    if (r.type === "Schema" && decoded) {
      schemas.set(r.id, new MessageReader(r.name, parseIDL(new TextDecoder().decode(r.data))));
    }
    if (r.type === "Channel") channels.set(r.id, r);
    if (r.type === "Message") {
      const channel = channels.get(r.channelId);
      if (!topics.has(channel.topic)) topics.set(channel.topic, []);
      topics.get(channel.topic).push(decoded ? text(schemas.get(channel.schemaId).readMessage(r.data))
                                             : Buffer.from(r.data).toString("hex"));
    }
  }
  return topics;
}

const [a, b] = [byTopic(process.argv[2]), byTopic(process.argv[3])];
let same = a.size === b.size, total = 0;
for (const [topic, messages] of a) {
  const other = b.get(topic) ?? [];
  const equal = other.length === messages.length && messages.every((m, k) => m === other[k]);
  if (!equal) console.log(`FAIL: ${topic}: ${messages.length} messages against ${other.length}` +
                          (other.length === messages.length ? " (payloads differ)" : ""));
  if (!equal && other.length === messages.length) {
    const k = messages.findIndex((m, i) => m !== other[i]);
    console.log(`  message ${k}: ${messages[k].slice(0, 400)}\n  against    ${other[k].slice(0, 400)}`);
  }
  same = same && equal;
  total += messages.length;
}
const what = process.argv[4] && process.argv[4] !== "--decoded" ? process.argv[4] : "canyon play: recorded again";
console.log(`${what}: ${a.size} topics, ${total} messages ` +
            (same ? `the same ${decoded ? "decoded" : "byte for byte"}: PASS` : "differ"));
process.exit(same ? 0 : 1);
