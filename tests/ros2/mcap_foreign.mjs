// An MCAP file canyon did not write (written by @mcap/core's writer): the solutions of a canyon session plus a channel
// of a type canyon does not know ("foo::msg::Bar" on "foo/bar"), in @mcap/core's uncompressed chunks, for canyon play's
// bad-input test.
// Usage: node mcap_foreign.mjs SESSION.mcap OUT.mcap

import fs from "node:fs";
import { McapStreamReader, McapWriter } from "@mcap/core";
import { decompressHandlers } from "./mcap_zstd.mjs";

const reader = new McapStreamReader({ validateCrcs: true, decompressHandlers });
reader.append(fs.readFileSync(process.argv[2]));
const chunks = [];
let position = 0n;
const writer = new McapWriter({
  writable: {
    position: () => position,
    write: async (buffer) => { chunks.push(Buffer.from(buffer)); position += BigInt(buffer.byteLength); },
  },
  useChunks: true,  // uncompressed chunks with Schema and Channel records inside, as @mcap/core writes them
});
await writer.start({ profile: "", library: "mcap_foreign.mjs" });
const channels = new Map();
for (let r; (r = reader.nextRecord()) !== undefined;) {
  if (r.type === "Channel" && r.topic === "canyon/solution" && !channels.has(r.id)) channels.set(r.id, r);
  if (r.type === "Schema" && r.name === "canyon::msg::Solution" && !channels.has("schema")) channels.set("schema", r);
  if (r.type === "Message" && channels.has(r.channelId)) {
    if (!channels.has("out")) {
      const s = channels.get("schema");
      const schemaId = await writer.registerSchema({ name: s.name, encoding: s.encoding, data: s.data });
      channels.set("out", await writer.registerChannel({ topic: "canyon/solution", schemaId, messageEncoding: "cdr", metadata: new Map() }));
      const foreign = await writer.registerSchema({ name: "foo::msg::Bar", encoding: "omgidl",
                                                    data: new TextEncoder().encode("module foo { module msg { struct Bar { long x; }; }; };") });
      const bar = await writer.registerChannel({ topic: "foo/bar", schemaId: foreign, messageEncoding: "cdr", metadata: new Map() });
      await writer.addMessage({ channelId: bar, sequence: 0, logTime: r.logTime, publishTime: r.logTime,
                                data: new Uint8Array([0, 1, 0, 0, 7, 0, 0, 0]) });
    }
    await writer.addMessage({ channelId: channels.get("out"), sequence: r.sequence, logTime: r.logTime,
                              publishTime: r.publishTime, data: r.data });
  }
}
await writer.end();
fs.writeFileSync(process.argv[3], Buffer.concat(chunks));
