// The MCAP writer and reader (io/mcap.hpp): a recording read back whole, its byte layout where the spec fixes it
// (magic, opcodes, little-endian lengths), a file cut short (an error naming the byte; the partial read keeps every
// message before the cut), not an MCAP file, an unwritable path. Chunked zstd: several chunks and channels read back
// whole, the Chunk Indexes and Message Indexes of the summary, a file cut inside a chunk, a corrupt chunk, an lz4 and
// an uncompressed chunk built by hand; unchunked (compression "") is byte for byte the writer's output before chunks.
// tests/ros2/mcap_check.mjs reads canyon's files with the independent MCAP reader of the npm registry.

#include "canyon/io/mcap.hpp"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <zlib.h>
#include <zstd.h>

#include "integration/test_support.hpp"

namespace canyon::io {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

const McapWriterOptions kUnchunked{.compression = ""};

fs::path session(int messages, const McapWriterOptions& options = {}) {
  const std::string name = "session" + std::to_string(messages) + (options.compression.empty() ? "" : "z") + ".mcap";
  fs::path path = test::temp_dir("mcap") / name;
  auto w = McapWriter::create(path.string(), options);
  EXPECT_TRUE(w) << w.error().to_string();
  const auto schema = w->add_schema("canyon::msg::Solution", "omgidl", "module canyon { };");
  const auto channel = w->add_channel(*schema, "canyon/solution", "cdr");
  for (int k = 0; k < messages; ++k) {
    McapMessage m;
    m.channel_id = *channel;
    m.sequence = static_cast<std::uint32_t>(k);
    m.log_time_ns = 1000000000ULL + static_cast<std::uint64_t>(k) * 200000000ULL;
    m.publish_time_ns = m.log_time_ns - 1000;
    m.data = {0x00, 0x01, 0x00, 0x00, static_cast<std::uint8_t>(k)};
    EXPECT_TRUE(w->write(m));
  }
  EXPECT_TRUE(w->close());
  return path;
}

std::uint64_t le_at(const std::string& bytes, std::size_t at, int size) {
  std::uint64_t v = 0;
  for (int i = 0; i < size; ++i) {
    v |= static_cast<std::uint64_t>(static_cast<std::uint8_t>(bytes.at(at + static_cast<std::size_t>(i)))) << (8 * i);
  }
  return v;
}
std::string le_bytes(std::uint64_t value, int size) {
  std::string out;
  for (int i = 0; i < size; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFFU));
  return out;
}
std::string mcap_string(const std::string& s) {
  return le_bytes(s.size(), 4) + s;
}
std::string mcap_record(std::uint8_t opcode, const std::string& content) {
  return std::string(1, static_cast<char>(opcode)) + le_bytes(content.size(), 8) + content;
}

/// A record of a file: opcode, where it starts, its length in all (opcode and length prefix included).
struct RecordAt {
  std::uint8_t opcode = 0;
  std::size_t at = 0;
  std::size_t size = 0;
};
/// The records from byte `from` to byte `to` (the test's own walk, not the reader's).
std::vector<RecordAt> records_in(const std::string& bytes, std::size_t from, std::size_t to) {
  std::vector<RecordAt> out;
  for (std::size_t at = from; at + 9 <= to;) {
    const RecordAt r{static_cast<std::uint8_t>(bytes[at]), at, 9 + static_cast<std::size_t>(le_at(bytes, at + 1, 8))};
    out.push_back(r);
    at += r.size;
  }
  return out;
}

/// A recording on three channels (two schemas) with payloads shaped like CDR samples (encapsulation header,
/// sequence, a few slowly changing doubles): what canyon record writes, small enough for a unit test.
struct Recording {
  fs::path path;
  std::vector<McapMessage> messages;
};
Recording three_channels(const std::string& name, const McapWriterOptions& options, int messages,
                         std::size_t random_bytes = 0) {
  Recording rec{test::temp_dir("mcap") / name, {}};
  auto w = McapWriter::create(rec.path.string(), options);
  EXPECT_TRUE(w) << w.error().to_string();
  const std::uint16_t solution = *w->add_schema("canyon::msg::Solution", "omgidl", "module canyon { };");
  const std::uint16_t imu = *w->add_schema("canyon::msg::Imu", "omgidl", "module canyon { module msg { }; };");
  const std::vector<std::uint16_t> channels{*w->add_channel(solution, "canyon/solution", "cdr"),
                                            *w->add_channel(solution, "canyon/float", "cdr"),
                                            *w->add_channel(imu, "canyon/imu", "cdr")};
  std::mt19937 random(29);
  std::map<std::uint16_t, std::uint32_t> sequence;
  for (int k = 0; k < messages; ++k) {
    McapMessage m;
    m.channel_id = channels[static_cast<std::size_t>(k % 4 == 3 ? 2 : k % 4)];  // IMU twice as often
    m.sequence = sequence[m.channel_id]++;
    m.log_time_ns = 1700000000000000000ULL + static_cast<std::uint64_t>(k) * 5000000ULL;
    m.publish_time_ns = m.log_time_ns - 2000 - static_cast<std::uint64_t>(k % 7);
    m.data = {0x00, 0x01, 0x00, 0x00};
    for (int b = 0; b < 4; ++b) m.data.push_back(static_cast<std::uint8_t>(m.sequence >> (8 * b)));
    for (int d = 0; d < 6 + 4 * m.channel_id; ++d) {
      const double value = 1000.0 * d + 0.001 * k;
      const auto* raw = reinterpret_cast<const std::uint8_t*>(&value);
      m.data.insert(m.data.end(), raw, raw + sizeof value);
    }
    for (std::size_t b = 0; b < random_bytes; ++b) m.data.push_back(static_cast<std::uint8_t>(random()));
    EXPECT_TRUE(w->write(m));
    rec.messages.push_back(m);
  }
  EXPECT_TRUE(w->close());
  return rec;
}

void expect_same_messages(const std::vector<McapMessage>& read, const std::vector<McapMessage>& written,
                          std::size_t count) {
  ASSERT_GE(read.size(), count);
  ASSERT_GE(written.size(), count);
  for (std::size_t k = 0; k < count; ++k) {
    SCOPED_TRACE("message " + std::to_string(k));
    EXPECT_EQ(read[k].channel_id, written[k].channel_id);
    EXPECT_EQ(read[k].sequence, written[k].sequence);
    EXPECT_EQ(read[k].log_time_ns, written[k].log_time_ns);
    EXPECT_EQ(read[k].publish_time_ns, written[k].publish_time_ns);
    EXPECT_EQ(read[k].data, written[k].data);
  }
}

/// The Chunk Index records of a file's summary and its Statistics' chunk_count.
struct Summary {
  std::vector<RecordAt> chunk_indexes;
  std::uint64_t chunk_count = 0;
  std::map<std::uint8_t, std::pair<std::uint64_t, std::uint64_t>> groups;  ///< SummaryOffsets: opcode -> start, length
};
Summary summary_of(const std::string& bytes) {
  Summary s;
  const std::size_t footer = bytes.size() - 8 - 29;
  const auto summary_start = static_cast<std::size_t>(le_at(bytes, footer + 9, 8));
  const auto offsets_start = static_cast<std::size_t>(le_at(bytes, footer + 17, 8));
  for (const RecordAt& r : records_in(bytes, summary_start, offsets_start)) {
    if (r.opcode == 0x08) s.chunk_indexes.push_back(r);
    if (r.opcode == 0x0B) s.chunk_count = le_at(bytes, r.at + 9 + 8 + 2 + 4 + 4 + 4, 4);
  }
  for (const RecordAt& r : records_in(bytes, offsets_start, footer)) {
    s.groups[static_cast<std::uint8_t>(bytes[r.at + 9])] = {le_at(bytes, r.at + 10, 8), le_at(bytes, r.at + 18, 8)};
  }
  return s;
}

TEST(Mcap, ARecordingReadsBackWhole) {
  const fs::path path = session(5);
  auto content = read_mcap(path.string());
  ASSERT_TRUE(content) << content.error().to_string();
  EXPECT_TRUE(content->complete);
  ASSERT_EQ(content->schemas.size(), 1U);
  EXPECT_EQ(content->schemas.at(1).name, "canyon::msg::Solution");
  EXPECT_EQ(content->schemas.at(1).encoding, "omgidl");
  ASSERT_EQ(content->channels.size(), 1U);
  EXPECT_EQ(content->channels.at(0).topic, "canyon/solution");
  EXPECT_EQ(content->channels.at(0).message_encoding, "cdr");
  ASSERT_EQ(content->messages.size(), 5U);
  EXPECT_EQ(content->messages[3].sequence, 3U);
  EXPECT_EQ(content->messages[3].log_time_ns, 1600000000ULL);
  EXPECT_EQ(content->messages[3].publish_time_ns, 1599999000ULL);
  EXPECT_EQ(content->messages[3].data, (std::vector<std::uint8_t>{0x00, 0x01, 0x00, 0x00, 0x03}));
}

TEST(Mcap, TheLayoutIsTheSpecs) {
  for (const McapWriterOptions& options : {kUnchunked, McapWriterOptions{}}) {
    SCOPED_TRACE("compression '" + options.compression + "'");
    const std::string bytes = slurp(session(1, options));
    const std::string magic("\x89MCAP0\r\n", 8);
    EXPECT_EQ(bytes.substr(0, 8), magic);
    EXPECT_EQ(bytes.substr(bytes.size() - 8), magic);
    EXPECT_EQ(bytes[8], '\x01');  // Header
    // Header content: profile "" (4-byte length 0) and library "canyon": 4 + 4 + 6 = 14 bytes.
    EXPECT_EQ(bytes.substr(9, 8), std::string("\x0e\0\0\0\0\0\0\0", 8));
    EXPECT_EQ(bytes.substr(17 + 4, 4), std::string("\x06\0\0\0", 4));
    EXPECT_EQ(bytes.substr(17 + 8, 6), "canyon");
    EXPECT_EQ(bytes[31], '\x03');  // the Schema comes next, before its Channel and the Message (or their Chunk)
    // The Footer: opcode 0x02, length 20, just before the closing magic.
    EXPECT_EQ(bytes[bytes.size() - 8 - 29], '\x02');
    EXPECT_EQ(bytes.substr(bytes.size() - 8 - 28, 8), std::string("\x14\0\0\0\0\0\0\0", 8));
  }
}

TEST(Mcap, AFileCutShortNamesTheByteAndKeepsWhatCameBefore) {
  const fs::path path = session(10, kUnchunked);
  const std::string bytes = slurp(path);
  const fs::path cut = path.parent_path() / "cut.mcap";
  // Cut inside the 8th message: everything after the first 7 messages' records is gone.
  // A message record: opcode 0x05, length 27 (channel 2, sequence 4, two times 8, data 5), 36 bytes in all.
  const std::size_t first = bytes.find(std::string("\x05\x1b\0\0\0\0\0\0\0", 9));
  ASSERT_NE(first, std::string::npos);
  const std::size_t at = first + std::size_t{7} * 36;
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, at + 20);
  const auto whole = read_mcap(cut.string());
  ASSERT_FALSE(whole);
  EXPECT_NE(whole.error().to_string().find("cut short at byte " + std::to_string(at)), std::string::npos)
      << whole.error().to_string();
  EXPECT_NE(whole.error().to_string().find("the 7 messages before it were read"), std::string::npos);
  std::string problem;
  const auto partial = read_mcap_partial(cut.string(), &problem);
  ASSERT_TRUE(partial);
  EXPECT_FALSE(partial->complete);
  EXPECT_EQ(partial->messages.size(), 7U);
  EXPECT_NE(problem.find("cut.mcap"), std::string::npos);
}

TEST(Mcap, AnUnchunkedFileIsByteForByteTheWriterBeforeChunks) {
  // Size and CRC32 of session(5) as the writer wrote it before it chunked (commit e16cabc).
  const std::string bytes = slurp(session(5, kUnchunked));
  EXPECT_EQ(bytes.size(), 626U);
  EXPECT_EQ(crc32_z(0L, reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()), 0xcc4d42d7UL);
  for (const RecordAt& r : records_in(bytes, 8, bytes.size() - 8)) EXPECT_NE(r.opcode, 0x06) << "a Chunk at " << r.at;
}

TEST(Mcap, ChunkedZstdReadsBackEveryMessageOfEveryChannel) {
  const Recording chunked = three_channels("chunked.mcap", {.chunk_size = 4096}, 800);
  const Recording unchunked = three_channels("unchunked.mcap", kUnchunked, 800);
  for (const Recording* rec : {&chunked, &unchunked}) {
    SCOPED_TRACE(rec->path.string());
    auto content = read_mcap(rec->path.string());
    ASSERT_TRUE(content) << content.error().to_string();
    EXPECT_TRUE(content->complete);
    ASSERT_EQ(content->schemas.size(), 2U);
    ASSERT_EQ(content->channels.size(), 3U);
    EXPECT_EQ(content->channels.at(2).topic, "canyon/imu");
    EXPECT_EQ(content->channels.at(2).schema_id, 2U);
    ASSERT_EQ(content->messages.size(), 800U);
    expect_same_messages(content->messages, rec->messages, 800);
  }
  const std::string bytes = slurp(chunked.path);
  const Summary summary = summary_of(bytes);
  EXPECT_GT(summary.chunk_count, 10U);
  EXPECT_EQ(summary.chunk_indexes.size(), summary.chunk_count);
  // 67,811 bytes for 102,380 unchunked (1 MiB chunks: 47,344): the doubles' low bits barely compress.
  EXPECT_LT(bytes.size() * 4, fs::file_size(unchunked.path) * 3);
}

TEST(Mcap, TheChunkIndexesAndMessageIndexesPointAtTheirRecords) {
  const Recording rec = three_channels("indexed.mcap", {.chunk_size = 4096}, 800);
  const std::string bytes = slurp(rec.path);
  const Summary summary = summary_of(bytes);
  ASSERT_EQ(summary.groups.count(0x08), 1U);
  EXPECT_EQ(summary.groups.at(0x08).first, summary.chunk_indexes.front().at);
  EXPECT_EQ(summary.groups.at(0x08).second,
            summary.chunk_indexes.back().at + summary.chunk_indexes.back().size - summary.chunk_indexes.front().at);
  std::size_t indexed = 0;
  for (const RecordAt& ci : summary.chunk_indexes) {
    std::size_t at = ci.at + 9;
    const std::uint64_t start_ns = le_at(bytes, at, 8), end_ns = le_at(bytes, at + 8, 8);
    const auto chunk_at = static_cast<std::size_t>(le_at(bytes, at + 16, 8));
    const std::uint64_t chunk_length = le_at(bytes, at + 24, 8);
    SCOPED_TRACE("chunk at byte " + std::to_string(chunk_at));
    ASSERT_EQ(bytes[chunk_at], '\x06');
    EXPECT_EQ(9 + le_at(bytes, chunk_at + 1, 8), chunk_length);
    EXPECT_EQ(le_at(bytes, chunk_at + 9, 8), start_ns);
    EXPECT_EQ(le_at(bytes, chunk_at + 17, 8), end_ns);
    // The Chunk's records, decompressed here with zstd itself, and their CRC32.
    const std::uint64_t uncompressed_size = le_at(bytes, chunk_at + 25, 8);
    EXPECT_EQ(bytes.substr(chunk_at + 37, 8), std::string("\x04\0\0\0zstd", 8));
    const auto compressed_size = static_cast<std::size_t>(le_at(bytes, chunk_at + 45, 8));
    std::string records(uncompressed_size, '\0');
    ASSERT_EQ(ZSTD_decompress(records.data(), records.size(), bytes.data() + chunk_at + 53, compressed_size),
              uncompressed_size);
    EXPECT_EQ(crc32_z(0L, reinterpret_cast<const Bytef*>(records.data()), records.size()),
              le_at(bytes, chunk_at + 33, 4));
    // Its Message Indexes: each names a channel, its entries point at that channel's Message records.
    const std::uint64_t map_size = le_at(bytes, at + 32, 4);
    std::uint64_t index_length = 0;
    for (std::size_t e = at + 36; e < at + 36 + map_size; e += 10) {
      const std::uint64_t channel = le_at(bytes, e, 2);
      const auto index_at = static_cast<std::size_t>(le_at(bytes, e + 2, 8));
      ASSERT_EQ(bytes[index_at], '\x07');
      EXPECT_EQ(le_at(bytes, index_at + 9, 2), channel);
      index_length += 9 + le_at(bytes, index_at + 1, 8);
      const std::uint64_t entries = le_at(bytes, index_at + 11, 4) / 16;
      for (std::uint64_t k = 0; k < entries; ++k) {
        const std::uint64_t log_ns = le_at(bytes, index_at + 15 + 16 * k, 8);
        const auto offset = static_cast<std::size_t>(le_at(bytes, index_at + 23 + 16 * k, 8));
        ASSERT_EQ(records[offset], '\x05');
        EXPECT_EQ(le_at(records, offset + 9, 2), channel);
        EXPECT_EQ(le_at(records, offset + 15, 8), log_ns);
        ++indexed;
      }
    }
    at += 36 + map_size;
    EXPECT_EQ(le_at(bytes, at, 8), index_length);
    EXPECT_EQ(bytes.substr(at + 8, 8), std::string("\x04\0\0\0zstd", 8));
    EXPECT_EQ(le_at(bytes, at + 16, 8), compressed_size);
    EXPECT_EQ(le_at(bytes, at + 24, 8), uncompressed_size);
  }
  EXPECT_EQ(indexed, rec.messages.size());
}

TEST(Mcap, AFileCutInsideItsLastChunkKeepsTheChunksBefore) {
  const Recording rec = three_channels("cut_chunk.mcap", {.chunk_size = 4096}, 800);
  const std::string bytes = slurp(rec.path);
  const Summary summary = summary_of(bytes);
  const RecordAt& last_index = summary.chunk_indexes.back();
  const auto last_chunk = static_cast<std::size_t>(le_at(bytes, last_index.at + 9 + 16, 8));
  const auto last_length = static_cast<std::size_t>(le_at(bytes, last_index.at + 9 + 24, 8));
  const fs::path cut = rec.path.parent_path() / "cut_chunk_cut.mcap";
  const std::size_t cut_at = last_chunk + last_length / 2;
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, cut_at);
  // The messages before the last Chunk: those whose log time is before its first.
  const std::uint64_t last_start_ns = le_at(bytes, last_index.at + 9, 8);
  std::size_t before = 0;
  while (before < rec.messages.size() && rec.messages[before].log_time_ns < last_start_ns) ++before;
  ASSERT_GT(before, 700U);

  const auto whole = read_mcap(cut.string());
  ASSERT_FALSE(whole);
  EXPECT_NE(whole.error().to_string().find("cut short at byte " + std::to_string(last_chunk)), std::string::npos)
      << whole.error().to_string();
  std::string problem;
  const auto partial = read_mcap_partial(cut.string(), &problem);
  ASSERT_TRUE(partial) << partial.error().to_string();
  EXPECT_FALSE(partial->complete);
  EXPECT_NE(problem.find("cut short at byte " + std::to_string(last_chunk)), std::string::npos) << problem;
  EXPECT_NE(problem.find("end of the file at byte " + std::to_string(cut_at)), std::string::npos) << problem;
  // A Chunk of 4 KiB is one zstd block: cut in its middle, none of its messages can be recovered.
  EXPECT_EQ(partial->messages.size(), before) << problem;
  expect_same_messages(partial->messages, rec.messages, before);
}

TEST(Mcap, AChunkCutShortGivesUpTheMessagesOfItsWholeBlocks) {
  // One Chunk of ~640 KB of barely compressible messages: five zstd blocks (128 KiB each at most).
  const Recording rec = three_channels("one_chunk.mcap", {}, 600, 1000);
  const std::string bytes = slurp(rec.path);
  const std::size_t cut_at = bytes.size() * 9 / 10;
  const fs::path cut = rec.path.parent_path() / "one_chunk_cut.mcap";
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, cut_at);
  std::string problem;
  const auto partial = read_mcap_partial(cut.string(), &problem);
  ASSERT_TRUE(partial) << partial.error().to_string();
  EXPECT_FALSE(partial->complete);
  EXPECT_GT(partial->messages.size(), 300U) << problem;
  EXPECT_LT(partial->messages.size(), 600U) << problem;
  expect_same_messages(partial->messages, rec.messages, partial->messages.size());
  EXPECT_NE(problem.find(std::to_string(partial->messages.size()) + " whole messages recovered"), std::string::npos)
      << problem;
}

TEST(Mcap, ACorruptChunkIsAnErrorNamingItsByte) {
  const Recording rec = three_channels("corrupt.mcap", {.chunk_size = 4096}, 200);
  const std::string bytes = slurp(rec.path);
  const Summary summary = summary_of(bytes);
  ASSERT_GE(summary.chunk_indexes.size(), 2U);
  const auto chunk_at = static_cast<std::size_t>(le_at(bytes, summary.chunk_indexes[1].at + 9 + 16, 8));
  const auto compressed_size = static_cast<std::size_t>(le_at(bytes, chunk_at + 45, 8));
  const std::size_t data_byte = chunk_at + 53 + compressed_size / 2, crc_byte = chunk_at + 33;
  for (const std::size_t flip : {data_byte, crc_byte}) {
    SCOPED_TRACE("byte " + std::to_string(flip) + " flipped");
    std::string corrupt = bytes;
    corrupt[flip] = static_cast<char>(corrupt[flip] ^ 0x5A);
    const fs::path path = rec.path.parent_path() / "corrupt_flipped.mcap";
    std::ofstream(path, std::ios::binary) << corrupt;
    const auto read = read_mcap(path.string());
    ASSERT_FALSE(read);
    EXPECT_NE(read.error().to_string().find("corrupt_flipped.mcap: chunk at byte " + std::to_string(chunk_at)),
              std::string::npos)
        << read.error().to_string();
    std::string problem;
    EXPECT_FALSE(read_mcap_partial(path.string(), &problem));
    if (flip == crc_byte) {
      EXPECT_NE(read.error().to_string().find("CRC32"), std::string::npos) << read.error().to_string();
    }
  }
}

/// A file with one hand-built Chunk of `records` (uncompressed, whatever `compression` says) and no summary.
std::string hand_built(const std::string& compression, const std::string& records, std::size_t* chunk_at) {
  std::string file = std::string("\x89MCAP0\r\n", 8) + mcap_record(0x01, mcap_string("") + mcap_string("test"));
  *chunk_at = file.size();
  file += mcap_record(0x06, le_bytes(1, 8) + le_bytes(1, 8) + le_bytes(records.size(), 8) + le_bytes(0, 4) +
                                mcap_string(compression) + le_bytes(records.size(), 8) + records);
  file += mcap_record(0x0F, le_bytes(0, 4));
  file += mcap_record(0x02, le_bytes(0, 8) + le_bytes(0, 8) + le_bytes(0, 4));
  return file + std::string("\x89MCAP0\r\n", 8);
}

TEST(Mcap, AnLz4ChunkIsRefusedAndAnUncompressedChunkRead) {
  const std::string records =
      mcap_record(0x03, le_bytes(1, 2) + mcap_string("foo::Bar") + mcap_string("omgidl") + mcap_string("")) +
      mcap_record(0x04,
                  le_bytes(7, 2) + le_bytes(1, 2) + mcap_string("foo/bar") + mcap_string("cdr") + le_bytes(0, 4)) +
      mcap_record(0x05, le_bytes(7, 2) + le_bytes(3, 4) + le_bytes(1, 8) + le_bytes(1, 8) + "hello");
  const fs::path dir = test::temp_dir("mcap");
  std::size_t chunk_at = 0;
  std::ofstream(dir / "lz4.mcap", std::ios::binary) << hand_built("lz4", records, &chunk_at);
  const auto lz4 = read_mcap((dir / "lz4.mcap").string());
  ASSERT_FALSE(lz4);
  EXPECT_EQ(lz4.error().to_string(), (dir / "lz4.mcap").string() + ": chunk at byte " + std::to_string(chunk_at) +
                                         ": compression 'lz4' is not supported (canyon reads zstd and uncompressed)");
  std::ofstream(dir / "stored.mcap", std::ios::binary) << hand_built("", records, &chunk_at);
  const auto stored = read_mcap((dir / "stored.mcap").string());
  ASSERT_TRUE(stored) << stored.error().to_string();
  ASSERT_EQ(stored->messages.size(), 1U);
  EXPECT_EQ(stored->channels.at(7).topic, "foo/bar");
  EXPECT_EQ(stored->messages[0].sequence, 3U);
  EXPECT_EQ(std::string(stored->messages[0].data.begin(), stored->messages[0].data.end()), "hello");
}

TEST(Mcap, TheWriterOptionsAreChecked) {
  const std::string path = (test::temp_dir("mcap") / "options.mcap").string();
  const auto lz4 = McapWriter::create(path, {.compression = "lz4"});
  ASSERT_FALSE(lz4);
  EXPECT_NE(lz4.error().to_string().find("compression must be \"zstd\" or \"\" (none), not 'lz4'"), std::string::npos);
  const auto empty = McapWriter::create(path, {.chunk_size = 0});
  ASSERT_FALSE(empty);
  EXPECT_NE(empty.error().to_string().find("chunk_size must be > 0"), std::string::npos);
}

TEST(Mcap, NotAnMcapFileAndAnUnwritablePathAreErrors) {
  const fs::path other = test::temp_dir("mcap") / "other.mcap";
  std::ofstream(other) << "%  GPST latitude(deg)\n";
  const auto read = read_mcap(other.string());
  ASSERT_FALSE(read);
  EXPECT_NE(read.error().to_string().find("not an MCAP file"), std::string::npos);
  const auto write = McapWriter::create("/dev/null/session.mcap");
  ASSERT_FALSE(write);
  EXPECT_NE(write.error().to_string().find("/dev/null/session.mcap"), std::string::npos);
}

}  // namespace
}  // namespace canyon::io
