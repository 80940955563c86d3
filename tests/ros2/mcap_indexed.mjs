// canyon's chunked MCAP as an indexed reader (Foxglove, the mcap tools) takes it, without canyon's code:
// @mcap/core's McapIndexedReader reads the Footer, the summary (Schemas, Channels, Statistics, Chunk Indexes) and the
// Summary Offsets, then every message through the Chunk and Message Indexes: all topics at once, topic by topic and
// over a time range, each Chunk's CRC32 checked; the counts must agree with the Statistics and with EXPECTED. fzstd
// decompresses the zstd chunks.
//
// Usage: node mcap_indexed.mjs SESSION.mcap EXPECTED_MESSAGES   (exit 0 pass, 1 fail)

import fs from "node:fs";
import { McapIndexedReader } from "@mcap/core";
import { check, failures } from "./check.mjs";
import { decompressHandlers } from "./mcap_zstd.mjs";

const [file, expectedText] = process.argv.slice(2);
const handle = await fs.promises.open(file, "r");
const readable = {  // the reader reads where the indexes point
  size: async () => BigInt((await handle.stat()).size),
  read: async (offset, length) => {
    const buffer = new Uint8Array(Number(length));
    for (let done = 0; done < buffer.length;) {
      const { bytesRead } = await handle.read(buffer, done, buffer.length - done, Number(offset) + done);
      if (bytesRead === 0) throw new Error(`read past the end of ${file} at ${Number(offset) + done}`);
      done += bytesRead;
    }
    return buffer;
  },
};
const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
const stats = reader.statistics;
check(stats !== undefined, "a Statistics record in the summary");
check(reader.chunkIndexes.length > 0 && reader.chunkIndexes.length === stats?.chunkCount,
      `${reader.chunkIndexes.length} Chunk Indexes for a chunk_count of ${stats?.chunkCount}`);
check(reader.chunkIndexes.every((c) => c.compression === "zstd" && c.messageIndexOffsets.size > 0),
      "every Chunk Index: zstd, with Message Index offsets");
for (const opcode of [0x03, 0x04, 0x08, 0x0b]) {  // Schema, Channel, Chunk Index, Statistics
  check(reader.summaryOffsetsByOpcode.has(opcode), `a Summary Offset for opcode 0x${opcode.toString(16)}`);
}
const all = [];
for await (const m of reader.readMessages({ validateCrcs: true })) all.push(m);
check(BigInt(all.length) === stats?.messageCount && all.length === Number(expectedText),
      `${all.length} messages through the indexes, Statistics ${stats?.messageCount}, expected ${expectedText}`);
for (const [id, channel] of reader.channelsById) {
  let n = 0;
  for await (const m of reader.readMessages({ topics: [channel.topic], validateCrcs: true })) n += m.channelId === id;
  check(BigInt(n) === stats?.channelMessageCounts.get(id),
        `${channel.topic}: ${n} messages, Statistics ${stats?.channelMessageCounts.get(id)}`);
}
const times = all.map((m) => m.logTime).sort((a, b) => (a < b ? -1 : a > b ? 1 : 0));
const [from, to] = [times[Math.floor(times.length / 3)], times[Math.floor((2 * times.length) / 3)]];
let inRange = 0;
for await (const m of reader.readMessages({ startTime: from, endTime: to })) inRange += m.logTime >= from && m.logTime <= to;
check(inRange === times.filter((t) => t >= from && t <= to).length, `a time range: ${inRange} messages`);
await handle.close();
console.log(`MCAP indexed: ${reader.chunkIndexes.length} zstd chunks, ${reader.channelsById.size} channels, ` +
            `${all.length} messages through the Chunk and Message Indexes, by topic and by time: ` +
            (failures.length === 0 ? "PASS" : `${failures.length} failures`));
process.exit(failures.length === 0 ? 0 : 1);
