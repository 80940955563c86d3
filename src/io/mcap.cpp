// MCAP recordings (see mcap.hpp).

#include "canyon/io/mcap.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <zlib.h>
#include <zstd.h>

namespace canyon::io {
namespace {

constexpr char kMagic[] = "\x89MCAP0\r\n";
constexpr std::size_t kMagicSize = 8;
constexpr std::size_t kRecordHeaderSize = 9;  // opcode and content length
// zstd's default level: a live recorder keeps up at several hundred MB/s on one core and gets most of the ratio.
constexpr int kZstdLevel = 3;
enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

void le(std::string& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFFU));
}
void str(std::string& out, const std::string& s) {
  le(out, s.size(), 4);
  out += s;
}
std::string record(std::uint8_t opcode, const std::string& content) {
  std::string out(1, static_cast<char>(opcode));
  le(out, content.size(), 8);
  return out + content;
}
std::string schema_record(const McapSchema& s) {
  std::string c;
  le(c, s.id, 2);
  str(c, s.name);
  str(c, s.encoding);
  str(c, s.data);
  return record(kSchema, c);
}
std::string channel_record(const McapChannel& ch) {
  std::string c;
  le(c, ch.id, 2);
  le(c, ch.schema_id, 2);
  str(c, ch.topic);
  str(c, ch.message_encoding);
  std::string map;
  for (const auto& [k, v] : ch.metadata) {
    str(map, k);
    str(map, v);
  }
  str(c, map);
  return record(kChannel, c);
}

std::string message_record(const McapMessage& m) {
  std::string c;
  le(c, m.channel_id, 2);
  le(c, m.sequence, 4);
  le(c, m.log_time_ns, 8);
  le(c, m.publish_time_ns, 8);
  c.append(reinterpret_cast<const char*>(m.data.data()), m.data.size());
  return record(kMessage, c);
}
/// The Message Index of one channel in a Chunk: (log time, offset of the Message in the uncompressed records).
std::string message_index_record(std::uint16_t channel_id,
                                 const std::vector<std::pair<std::uint64_t, std::uint64_t>>& entries) {
  std::string c;
  le(c, channel_id, 2);
  le(c, entries.size() * 16, 4);
  for (const auto& [log_ns, offset] : entries) {
    le(c, log_ns, 8);
    le(c, offset, 8);
  }
  return record(kMessageIndex, c);
}
/// CRC32 (zlib's, the one the spec names) of a whole buffer; crc32_z takes a size_t length.
std::uint32_t crc32_of(const void* data, std::size_t size) {
  return static_cast<std::uint32_t>(crc32_z(0L, static_cast<const Bytef*>(data), size));
}

/// A little-endian cursor over a record's content; `ok` false once a read ran past its end.
struct Cursor {
  const std::uint8_t* p;
  std::size_t n;
  std::size_t at = 0;
  bool ok = true;
  std::uint64_t u(int bytes) {
    if (at + static_cast<std::size_t>(bytes) > n) {
      ok = false;
      return 0;
    }
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(p[at + static_cast<std::size_t>(i)]) << (8 * i);
    at += static_cast<std::size_t>(bytes);
    return v;
  }
  std::string s() {
    const std::uint64_t len = u(4);
    if (!ok || at + len > n) {
      ok = false;
      return {};
    }
    std::string out(reinterpret_cast<const char*>(p + at), len);
    at += len;
    return out;
  }
};

/// Adds a Schema, Channel or Message record (`body`: its content) to `content`; other records are skipped. `where`
/// places the record in the file for errors ("at byte N", "at byte K of the records of the chunk at byte N").
Status take_record(std::uint8_t opcode, const std::uint8_t* body, std::size_t length, const std::string& where,
                   const std::string& path, McapContent& content) {
  Cursor c{body, length};
  if (opcode == kSchema) {
    McapSchema s;
    s.id = static_cast<std::uint16_t>(c.u(2));
    s.name = c.s();
    s.encoding = c.s();
    s.data = c.s();
    if (!c.ok) return Error{"a Schema record is malformed " + where, path, 0};
    content.schemas[s.id] = s;
  } else if (opcode == kChannel) {
    McapChannel ch;
    ch.id = static_cast<std::uint16_t>(c.u(2));
    ch.schema_id = static_cast<std::uint16_t>(c.u(2));
    ch.topic = c.s();
    ch.message_encoding = c.s();
    if (!c.ok) return Error{"a Channel record is malformed " + where, path, 0};
    content.channels[ch.id] = ch;
  } else if (opcode == kMessage) {
    McapMessage m;
    m.channel_id = static_cast<std::uint16_t>(c.u(2));
    m.sequence = static_cast<std::uint32_t>(c.u(4));
    m.log_time_ns = c.u(8);
    m.publish_time_ns = c.u(8);
    if (!c.ok) return Error{"a Message record is malformed " + where, path, 0};
    if (content.channels.count(m.channel_id) == 0) {
      return Error{"a Message " + where + " is on channel " + std::to_string(m.channel_id) +
                       ", which no Channel record before it defines",
                   path, 0};
    }
    m.data.assign(body + c.at, body + length);
    content.messages.push_back(std::move(m));
  }
  return Ok{};
}

/// A Chunk record's fields before its records.
struct ChunkHeader {
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;  ///< 0: not computed
  std::string compression;             ///< "zstd", "lz4", "" (none)
  std::uint64_t records_size = 0;      ///< the (compressed) records' length
  std::size_t records_at = 0;          ///< where the records start in the record's content
};

/// The fields of a Chunk record from the first `available` bytes of its content; nullopt when they are not all there.
std::optional<ChunkHeader> read_chunk_header(const std::uint8_t* body, std::size_t available) {
  Cursor c{body, available};
  ChunkHeader h;
  c.u(8);  // message_start_time
  c.u(8);  // message_end_time
  h.uncompressed_size = c.u(8);
  h.uncompressed_crc = static_cast<std::uint32_t>(c.u(4));
  h.compression = c.s();
  h.records_size = c.u(8);
  h.records_at = c.at;
  if (!c.ok) return std::nullopt;
  return h;
}

/// Decompresses zstd data, at most `limit` bytes out (the Chunk's uncompressed_size: a corrupt or lying Chunk never
/// makes the reader allocate more). The streaming decoder gives the output of every complete block it was fed, so
/// a Chunk cut short (`whole` false) yields its records up to the last whole block before the cut.
Result<std::vector<std::uint8_t>> zstd_decompress(const std::uint8_t* data, std::size_t size, std::uint64_t limit,
                                                  bool whole) {
  const std::unique_ptr<ZSTD_DCtx, std::size_t (*)(ZSTD_DCtx*)> stream(ZSTD_createDCtx(), &ZSTD_freeDCtx);
  if (!stream) return Error{"cannot allocate a zstd decoder"};
  ZSTD_inBuffer in{data, size, 0};
  std::vector<std::uint8_t> out;
  const std::size_t step = ZSTD_DStreamOutSize();
  std::size_t frame_left = 0;  // ZSTD_decompressStream's hint: 0 once a frame is complete
  for (;;) {
    const std::size_t had = out.size();
    out.resize(had + step);
    ZSTD_outBuffer chunk_out{out.data() + had, step, 0};
    frame_left = ZSTD_decompressStream(stream.get(), &chunk_out, &in);
    out.resize(had + chunk_out.pos);
    if (ZSTD_isError(frame_left) != 0U) {
      return Error{std::string("its zstd data is corrupt (") + ZSTD_getErrorName(frame_left) + ")"};
    }
    if (out.size() > limit) {
      return Error{"its zstd data decompresses to more than its uncompressed_size of " + std::to_string(limit) +
                   " bytes"};
    }
    // Done once all input is taken and the decoder no longer fills the output it is given.
    if (in.pos == in.size && chunk_out.pos < chunk_out.size) break;
  }
  if (whole && frame_left != 0) return Error{"its zstd data ends inside a zstd frame"};
  return out;
}

/// The records of a Chunk, decompressed (see zstd_decompress for `whole`). Errors carry no place: the caller adds
/// the Chunk's.
Result<std::vector<std::uint8_t>> chunk_records(const ChunkHeader& h, const std::uint8_t* data, std::size_t size,
                                                bool whole) {
  if (h.compression.empty()) return std::vector<std::uint8_t>(data, data + size);
  if (h.compression != "zstd") {
    return Error{"compression '" + h.compression + "' is not supported (canyon reads zstd and uncompressed)"};
  }
  return zstd_decompress(data, size, h.uncompressed_size, whole);
}

std::string chunk_place(std::size_t chunk_at) {
  return "chunk at byte " + std::to_string(chunk_at);
}
std::string hex32(std::uint32_t value) {
  std::array<char, 11> text{};
  std::snprintf(text.data(), text.size(), "0x%08x", static_cast<unsigned>(value));
  return text.data();
}

/// Takes the Schema, Channel and Message records among a Chunk's decompressed records; returns the messages taken.
/// `cut`: the records stop where the file was cut, and an incomplete last record is dropped rather than an error.
Result<std::size_t> take_chunk_records(const std::vector<std::uint8_t>& records, std::size_t chunk_at, bool cut,
                                       const std::string& path, McapContent& content) {
  const std::size_t messages_before = content.messages.size();
  std::size_t at = 0;
  while (at < records.size()) {
    const std::size_t left = records.size() - at;
    const std::uint64_t length = left >= kRecordHeaderSize ? Cursor{records.data() + at + 1, 8}.u(8) : 0;
    const std::string where = "at byte " + std::to_string(at) + " of the records of the " + chunk_place(chunk_at);
    if (left < kRecordHeaderSize || length > left - kRecordHeaderSize) {
      if (cut) break;
      return Error{"a record " + where + " runs past their end", path, 0};
    }
    const std::uint8_t* body = records.data() + at + kRecordHeaderSize;
    if (Status s = take_record(records[at], body, static_cast<std::size_t>(length), where, path, content); !s) {
      return s.error();
    }
    at += kRecordHeaderSize + static_cast<std::size_t>(length);
  }
  return content.messages.size() - messages_before;
}

/// Takes the records of a whole Chunk record (content `body`, `length` bytes, at byte `chunk_at` of the file) after
/// checking its records against the uncompressed size and CRC32 of its header.
Status take_chunk(const std::uint8_t* body, std::size_t length, std::size_t chunk_at, const std::string& path,
                  McapContent& content) {
  const std::string place = chunk_place(chunk_at) + ": ";
  const std::optional<ChunkHeader> h = read_chunk_header(body, length);
  if (!h || h->records_size > length - h->records_at) return Error{place + "the Chunk record is malformed", path, 0};
  auto records = chunk_records(*h, body + h->records_at, static_cast<std::size_t>(h->records_size), true);
  if (!records) return Error{place + records.error().message, path, 0};
  if (records->size() != h->uncompressed_size) {
    return Error{place + "its records are " + std::to_string(records->size()) + " bytes, its uncompressed_size says " +
                     std::to_string(h->uncompressed_size),
                 path, 0};
  }
  if (h->uncompressed_crc != 0) {
    const std::uint32_t crc = crc32_of(records->data(), records->size());
    if (crc != h->uncompressed_crc) {
      return Error{place + "the CRC32 of its records is " + hex32(crc) + ", its uncompressed_crc says " +
                       hex32(h->uncompressed_crc) + " (corrupt data)",
                   path, 0};
    }
  }
  auto taken = take_chunk_records(*records, chunk_at, false, path, content);
  if (!taken) return taken.error();
  return Ok{};
}

/// A Chunk record at byte `chunk_at` whose `length` bytes of content run past the end of the file at `file_end`
/// (`available` of them are there): takes the whole messages that the complete zstd blocks before the cut hold and
/// returns the problem text. Their CRC cannot be checked (it covers the whole records). An Error when the part that
/// is there does not decompress or is compressed otherwise.
Result<std::string> take_cut_chunk(const std::uint8_t* body, std::size_t available, std::uint64_t length,
                                   std::size_t chunk_at, std::size_t file_end, const std::string& path,
                                   McapContent& content) {
  std::string cut = "cut short at byte " + std::to_string(chunk_at) + " (a Chunk record of " + std::to_string(length) +
                    " bytes runs past the end of the file at byte " + std::to_string(file_end);
  const std::optional<ChunkHeader> h = read_chunk_header(body, available);
  if (!h) return cut + "; its header is incomplete)";
  const std::size_t there =
      static_cast<std::size_t>(std::min<std::uint64_t>(h->records_size, available - h->records_at));
  auto records = chunk_records(*h, body + h->records_at, there, false);
  if (!records) return Error{chunk_place(chunk_at) + ": " + records.error().message, path, 0};
  auto taken = take_chunk_records(*records, chunk_at, true, path, content);
  if (!taken) return taken.error();
  return cut + "; " + std::to_string(*taken) + " whole messages recovered from the first " +
         std::to_string(records->size()) + " of its " + std::to_string(h->uncompressed_size) + " uncompressed bytes)";
}

}  // namespace

Status McapWriterOptions::validate() const {
  if (compression != "zstd" && !compression.empty()) {
    return Error{"MCAP compression must be \"zstd\" or \"\" (none), not '" + compression + "'"};
  }
  if (chunk_size == 0) return Error{"MCAP chunk_size must be > 0"};
  return Ok{};
}

Result<McapWriter> McapWriter::create(const std::string& path, const McapWriterOptions& options) {
  if (Status valid = options.validate(); !valid) return Error{valid.error().message, path, 0};
  std::error_code ec;
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "wb"));
  if (!file) return Error{std::string("cannot create the MCAP file: ") + std::strerror(errno), path, 0};
  McapWriter w(std::move(file), path, options);
  std::string head(kMagic, kMagicSize);
  std::string header;
  str(header, "");  // profile
  str(header, "canyon");
  head += record(kHeader, header);
  if (Status s = w.put(head); !s) return s.error();
  return w;
}

Status McapWriter::put(const std::string& bytes) {
  if (closed_ || !file_) return Error{"MCAP file already closed", path_, 0};
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_.get()) != bytes.size()) {
    return Error{std::string("cannot write the MCAP file: ") + std::strerror(errno), path_, 0};
  }
  offset_ += bytes.size();
  return Ok{};
}

Result<std::uint16_t> McapWriter::add_schema(const std::string& name, const std::string& encoding,
                                             const std::string& data) {
  McapSchema s{static_cast<std::uint16_t>(schemas_.size() + 1), name, encoding, data};
  if (Status st = put(schema_record(s)); !st) return st.error();
  schemas_.push_back(s);
  return s.id;
}

Result<std::uint16_t> McapWriter::add_channel(std::uint16_t schema_id, const std::string& topic,
                                              const std::string& message_encoding) {
  McapChannel ch{static_cast<std::uint16_t>(channels_.size()), schema_id, topic, message_encoding, {}};
  if (Status st = put(channel_record(ch)); !st) return st.error();
  channels_.push_back(ch);
  channel_counts_[ch.id] = 0;
  return ch.id;
}

Status McapWriter::write(const McapMessage& m) {
  if (closed_ || !file_) return Error{"MCAP file already closed", path_, 0};
  if (m.channel_id >= channels_.size()) return Error{"MCAP message on an unknown channel", path_, 0};
  const std::string message = message_record(m);
  if (chunked()) {
    if (chunk_.records.empty() || m.log_time_ns < chunk_.start_ns) chunk_.start_ns = m.log_time_ns;
    if (chunk_.records.empty() || m.log_time_ns > chunk_.end_ns) chunk_.end_ns = m.log_time_ns;
    chunk_.index[m.channel_id].emplace_back(m.log_time_ns, chunk_.records.size());
    chunk_.records += message;
  } else if (Status s = put(message); !s) {
    return s;
  }
  if (message_count_ == 0 || m.log_time_ns < first_log_ns_) first_log_ns_ = m.log_time_ns;
  if (m.log_time_ns > last_log_ns_) last_log_ns_ = m.log_time_ns;
  ++message_count_;
  ++channel_counts_[m.channel_id];
  if (chunked() && chunk_.records.size() >= options_.chunk_size) return write_chunk();
  return Ok{};
}

Status McapWriter::write_chunk() {
  if (chunk_.records.empty()) return Ok{};
  std::string compressed(ZSTD_compressBound(chunk_.records.size()), '\0');
  const std::size_t compressed_size =
      ZSTD_compress(compressed.data(), compressed.size(), chunk_.records.data(), chunk_.records.size(), kZstdLevel);
  if (ZSTD_isError(compressed_size) != 0U) {
    return Error{std::string("cannot compress an MCAP chunk: ") + ZSTD_getErrorName(compressed_size), path_, 0};
  }
  compressed.resize(compressed_size);
  std::string c;
  le(c, chunk_.start_ns, 8);
  le(c, chunk_.end_ns, 8);
  le(c, chunk_.records.size(), 8);
  le(c, crc32_of(chunk_.records.data(), chunk_.records.size()), 4);
  str(c, options_.compression);
  le(c, compressed.size(), 8);
  c += compressed;
  const std::uint64_t chunk_at = offset_;
  const std::string chunk = record(kChunk, c);
  // One Message Index per channel in the Chunk, right after it; the Chunk Index maps each channel to its offset.
  std::string indexes, index_offsets;
  for (const auto& [channel_id, entries] : chunk_.index) {
    le(index_offsets, channel_id, 2);
    le(index_offsets, chunk_at + chunk.size() + indexes.size(), 8);
    indexes += message_index_record(channel_id, entries);
  }
  if (Status s = put(chunk); !s) return s;
  if (Status s = put(indexes); !s) return s;
  std::string ci;
  le(ci, chunk_.start_ns, 8);
  le(ci, chunk_.end_ns, 8);
  le(ci, chunk_at, 8);
  le(ci, chunk.size(), 8);
  str(ci, index_offsets);
  le(ci, indexes.size(), 8);
  str(ci, options_.compression);
  le(ci, compressed.size(), 8);
  le(ci, chunk_.records.size(), 8);
  chunk_indexes_ += record(kChunkIndex, ci);
  ++chunk_count_;
  chunk_ = OpenChunk{};
  return Ok{};
}

Status McapWriter::close() {
  if (closed_) return Ok{};
  if (Status s = write_chunk(); !s) return s;
  std::string data_end;
  le(data_end, 0, 4);  // data section CRC: not computed
  if (Status s = put(record(kDataEnd, data_end)); !s) return s;
  const std::uint64_t summary_start = offset_;
  std::string summary, offsets;
  const auto group = [&](std::uint8_t opcode, const std::string& records) {
    if (records.empty()) return;
    std::string c(1, static_cast<char>(opcode));
    le(c, summary_start + summary.size(), 8);
    le(c, records.size(), 8);
    offsets += record(kSummaryOffset, c);
    summary += records;
  };
  std::string schemas, channels;
  for (const McapSchema& s : schemas_) schemas += schema_record(s);
  for (const McapChannel& ch : channels_) channels += channel_record(ch);
  group(kSchema, schemas);
  group(kChannel, channels);
  group(kChunkIndex, chunk_indexes_);  // none unchunked: that summary stays as it was before chunks
  std::string stats;
  le(stats, message_count_, 8);
  le(stats, schemas_.size(), 2);
  le(stats, channels_.size(), 4);
  le(stats, 0, 4);  // attachments
  le(stats, 0, 4);  // metadata
  le(stats, chunk_count_, 4);
  le(stats, first_log_ns_, 8);
  le(stats, last_log_ns_, 8);
  std::string counts;
  for (const auto& [id, n] : channel_counts_) {
    le(counts, id, 2);
    le(counts, n, 8);
  }
  le(stats, counts.size(), 4);
  stats += counts;
  group(kStatistics, record(kStatistics, stats));
  const std::uint64_t summary_offset_start = summary_start + summary.size();
  std::string footer;
  le(footer, summary_start, 8);
  le(footer, summary_offset_start, 8);
  le(footer, 0, 4);  // summary CRC: not computed
  if (Status s = put(summary + offsets + record(kFooter, footer) + std::string(kMagic, kMagicSize)); !s) return s;
  closed_ = true;
  const bool failed = std::fflush(file_.get()) != 0 || std::ferror(file_.get()) != 0;
  file_.reset();
  if (failed) return Error{"cannot write the MCAP file (disk full?)", path_, 0};
  return Ok{};
}

Result<McapContent> read_mcap_partial(const std::string& path, std::string* problem) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{"cannot read the MCAP file", path, 0};
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < kMagicSize || std::memcmp(bytes.data(), kMagic, kMagicSize) != 0) {
    return Error{"not an MCAP file (no MCAP magic at byte 0)", path, 0};
  }
  McapContent content;
  std::size_t at = kMagicSize;
  bool data_ended = false;
  const auto cut = [&](const std::string& what) {
    if (problem != nullptr) *problem = path + ": " + what;
  };
  while (at < bytes.size()) {
    if (at + kRecordHeaderSize > bytes.size()) {
      cut("cut short at byte " + std::to_string(at) + " (a record header is incomplete)");
      return content;
    }
    const std::uint8_t opcode = bytes[at];
    const std::uint64_t length = Cursor{bytes.data() + at + 1, 8}.u(8);
    const std::uint8_t* body = bytes.data() + at + kRecordHeaderSize;
    const std::size_t left = bytes.size() - at - kRecordHeaderSize;
    if (length > left) {
      if (opcode != kChunk || data_ended) {
        cut("cut short at byte " + std::to_string(at) + " (a record of " + std::to_string(length) +
            " bytes runs past the end of the file)");
        return content;
      }
      auto text = take_cut_chunk(body, left, length, at, bytes.size(), path, content);
      if (!text) return text.error();
      cut(*text);
      return content;
    }
    const std::size_t record_at = at;
    at += kRecordHeaderSize + length;
    if (opcode == kFooter) {
      content.complete = at + kMagicSize == bytes.size() && std::memcmp(bytes.data() + at, kMagic, kMagicSize) == 0;
      if (!content.complete) cut("no closing magic after the footer at byte " + std::to_string(record_at));
      return content;
    }
    if (data_ended) continue;  // the summary repeats the data section's schemas and channels
    Status taken = Ok{};
    if (opcode == kDataEnd) {
      data_ended = true;
    } else if (opcode == kChunk) {
      taken = take_chunk(body, static_cast<std::size_t>(length), record_at, path, content);
    } else {
      taken = take_record(opcode, body, static_cast<std::size_t>(length), "at byte " + std::to_string(record_at), path,
                          content);
    }
    if (!taken) return taken.error();
  }
  cut("cut short at byte " + std::to_string(bytes.size()) + " (no footer)");
  return content;
}

Result<McapContent> read_mcap(const std::string& path) {
  std::string problem;
  auto content = read_mcap_partial(path, &problem);
  if (!content) return content;
  if (!content->complete) {
    return Error{problem.substr(problem.find(": ") + 2) + "; the " + std::to_string(content->messages.size()) +
                     " messages before it were read",
                 path, 0};
  }
  return content;
}

}  // namespace canyon::io
