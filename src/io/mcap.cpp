// MCAP recordings (see mcap.hpp).

#include "canyon/io/mcap.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace canyon::io {
namespace {

constexpr char kMagic[] = "\x89MCAP0\r\n";
constexpr std::size_t kMagicSize = 8;
enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
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

}  // namespace

Result<McapWriter> McapWriter::create(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "wb"));
  if (!file) return Error{std::string("cannot create the MCAP file: ") + std::strerror(errno), path, 0};
  McapWriter w(std::move(file), path);
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
  if (m.channel_id >= channels_.size()) return Error{"MCAP message on an unknown channel", path_, 0};
  std::string c;
  le(c, m.channel_id, 2);
  le(c, m.sequence, 4);
  le(c, m.log_time_ns, 8);
  le(c, m.publish_time_ns, 8);
  c.append(reinterpret_cast<const char*>(m.data.data()), m.data.size());
  if (Status s = put(record(kMessage, c)); !s) return s;
  if (message_count_ == 0 || m.log_time_ns < first_log_ns_) first_log_ns_ = m.log_time_ns;
  if (m.log_time_ns > last_log_ns_) last_log_ns_ = m.log_time_ns;
  ++message_count_;
  ++channel_counts_[m.channel_id];
  return Ok{};
}

Status McapWriter::close() {
  if (closed_) return Ok{};
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
  std::string stats;
  le(stats, message_count_, 8);
  le(stats, schemas_.size(), 2);
  le(stats, channels_.size(), 4);
  le(stats, 0, 4);  // attachments
  le(stats, 0, 4);  // metadata
  le(stats, 0, 4);  // chunks
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
    if (at + 9 > bytes.size()) {
      cut("cut short at byte " + std::to_string(at) + " (a record header is incomplete)");
      return content;
    }
    const std::uint8_t opcode = bytes[at];
    Cursor len{bytes.data() + at + 1, 8};
    const std::uint64_t length = len.u(8);
    if (length > bytes.size() - at - 9) {
      cut("cut short at byte " + std::to_string(at) + " (a record of " + std::to_string(length) +
          " bytes runs past the end of the file)");
      return content;
    }
    Cursor c{bytes.data() + at + 9, static_cast<std::size_t>(length)};
    const std::size_t record_at = at;
    at += 9 + length;
    if (opcode == kFooter) {
      content.complete = at + kMagicSize == bytes.size() && std::memcmp(bytes.data() + at, kMagic, kMagicSize) == 0;
      if (!content.complete) cut("no closing magic after the footer at byte " + std::to_string(record_at));
      return content;
    }
    if (data_ended) continue;  // the summary repeats the data section's schemas and channels
    if (opcode == kDataEnd) {
      data_ended = true;
    } else if (opcode == kSchema) {
      McapSchema s;
      s.id = static_cast<std::uint16_t>(c.u(2));
      s.name = c.s();
      s.encoding = c.s();
      s.data = c.s();
      if (!c.ok) return Error{"a Schema record is malformed at byte " + std::to_string(record_at), path, 0};
      content.schemas[s.id] = s;
    } else if (opcode == kChannel) {
      McapChannel ch;
      ch.id = static_cast<std::uint16_t>(c.u(2));
      ch.schema_id = static_cast<std::uint16_t>(c.u(2));
      ch.topic = c.s();
      ch.message_encoding = c.s();
      if (!c.ok) return Error{"a Channel record is malformed at byte " + std::to_string(record_at), path, 0};
      content.channels[ch.id] = ch;
    } else if (opcode == kMessage) {
      McapMessage m;
      m.channel_id = static_cast<std::uint16_t>(c.u(2));
      m.sequence = static_cast<std::uint32_t>(c.u(4));
      m.log_time_ns = c.u(8);
      m.publish_time_ns = c.u(8);
      if (!c.ok) return Error{"a Message record is malformed at byte " + std::to_string(record_at), path, 0};
      if (content.channels.count(m.channel_id) == 0) {
        return Error{"a Message at byte " + std::to_string(record_at) + " is on channel " +
                         std::to_string(m.channel_id) + ", which no Channel record before it defines",
                     path, 0};
      }
      m.data.assign(bytes.begin() + static_cast<std::ptrdiff_t>(record_at + 9 + c.at),
                    bytes.begin() + static_cast<std::ptrdiff_t>(at));
      content.messages.push_back(std::move(m));
    }
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
