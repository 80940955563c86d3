// Two MCAP recordings hold the same messages, byte for byte, topic by topic in order (read with @mcap/core, not
// canyon's code): a session played with canyon play and recorded again equals the original.
// Usage: node mcap_same.mjs A.mcap B.mcap   (exit 0 same, 1 different)

import fs from "node:fs";
import { McapStreamReader } from "@mcap/core";

function byTopic(file) {
  const reader = new McapStreamReader({ validateCrcs: true });
  reader.append(fs.readFileSync(file));
  const channels = new Map(), topics = new Map();
  for (let r; (r = reader.nextRecord()) !== undefined;) {
    if (r.type === "Channel") channels.set(r.id, r.topic);
    if (r.type === "Message") {
      const topic = channels.get(r.channelId);
      if (!topics.has(topic)) topics.set(topic, []);
      topics.get(topic).push(Buffer.from(r.data).toString("hex"));
    }
  }
  return topics;
}

const [a, b] = [byTopic(process.argv[2]), byTopic(process.argv[3])];
let same = a.size === b.size, total = 0;
for (const [topic, messages] of a) {
  const other = b.get(topic) ?? [];
  const equal = other.length === messages.length && messages.every((m, k) => m === other[k]);
  if (!equal) console.log(`FAIL: ${topic}: ${messages.length} messages, played and recorded again ${other.length}` +
                          (other.length === messages.length ? " (payloads differ)" : ""));
  same = same && equal;
  total += messages.length;
}
console.log(`canyon play: ${a.size} topics, ${total} messages recorded again ${same ? "byte for byte: PASS" : "differently"}`);
process.exit(same ? 0 : 1);
