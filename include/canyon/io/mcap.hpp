#pragma once
// MCAP recordings (https://mcap.dev/spec, version 0): the container Foxglove and the `mcap` tools open, written and
// read by canyon itself (no MCAP library is packaged for Debian 12).
//
// Writer: the magic, a Header (profile "", library "canyon"), then in the data section each Schema and Channel
// before its first Message (outside any Chunk: a reader of a file cut short finds them before the messages), the
// Messages in the order given, a DataEnd (data CRC 0: not computed), and a summary section: every Schema and Channel
// again, the Chunk Indexes, a Statistics record (message count, chunk count, first and last log time, messages per
// channel) and a SummaryOffset per group; the Footer and the magic.
// Messages are chunked by default (McapWriterOptions): they collect in a Chunk of about `chunk_size` uncompressed
// bytes, written zstd-compressed with the CRC32 of its records, followed by one Message Index per channel in it; the
// summary has a Chunk Index per Chunk, so indexed readers (Foxglove, @mcap/core's McapIndexedReader) seek by time.
// With compression "" the Messages are written one by one, unchunked and unindexed, byte for byte as canyon wrote
// them before it chunked (readers then scan the data section).
// canyon's schemas are OMG IDL ("omgidl", the IDL text of the type) with CDR-encoded messages ("cdr"): the serialized
// DDS payloads as they came off the wire, encapsulation header included.
// Reader: the data section in order (Schema, Channel, Message, and the same records inside each Chunk; other records
// skipped), so that a file cut short still yields every message before the cut. Chunks are zstd-compressed or
// uncompressed; their size and CRC32 are checked. Errors name the file and the byte offset: a bad magic, a record
// that runs past the end (a file cut short: the messages before it were read), a message on an unknown channel, a
// Chunk that does not decompress to its size and CRC or is compressed otherwise (lz4).

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "canyon/core/result.hpp"

namespace canyon::io {

struct McapSchema {
  std::uint16_t id = 0;
  std::string name;      ///< e.g. "canyon::msg::Solution"
  std::string encoding;  ///< "omgidl"
  std::string data;      ///< the IDL text
};

struct McapChannel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;             ///< the DDS topic, e.g. "canyon/solution"
  std::string message_encoding;  ///< "cdr"
  std::map<std::string, std::string> metadata;
};

struct McapMessage {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time_ns = 0;      ///< when canyon received it (ns since the UNIX epoch)
  std::uint64_t publish_time_ns = 0;  ///< the publisher's source timestamp (ns since the UNIX epoch)
  std::vector<std::uint8_t> data;
};

/// How McapWriter lays out the messages.
struct McapWriterOptions {
  /// "zstd": Messages in zstd-compressed, indexed Chunks; "": unchunked Messages (canyon's layout before chunks).
  std::string compression = "zstd";
  /// Uncompressed bytes of records a Chunk collects before it is written (its last message may take it past this).
  std::size_t chunk_size = std::size_t{1} << 20;

  /// The first broken rule: compression "zstd" or "", chunk_size > 0.
  [[nodiscard]] Status validate() const;
};

class McapWriter {
 public:
  /// Creates (truncates) `path`, creating its folder, and writes the magic and the Header. Chunked zstd by default.
  static Result<McapWriter> create(const std::string& path, const McapWriterOptions& options = {});
  McapWriter(McapWriter&&) noexcept = default;
  McapWriter& operator=(McapWriter&&) noexcept = default;
  ~McapWriter() = default;

  /// A schema; its id (1, 2, ...). Written now.
  Result<std::uint16_t> add_schema(const std::string& name, const std::string& encoding, const std::string& data);
  /// A channel on a schema; its id (0, 1, ...). Written now.
  Result<std::uint16_t> add_channel(std::uint16_t schema_id, const std::string& topic,
                                    const std::string& message_encoding);
  /// A message on a channel (sequence and times as given). Chunked, it reaches the file with its Chunk: when the
  /// Chunk is full or at close() (a writer destroyed without close() loses the open Chunk).
  Status write(const McapMessage& message);
  /// The open Chunk, the DataEnd, the summary, the Footer and the closing magic; reports a write error that happened
  /// on the way.
  Status close();
  [[nodiscard]] std::uint64_t messages() const { return message_count_; }
  /// Bytes written to the file so far (not counting the open Chunk).
  [[nodiscard]] std::uint64_t bytes() const { return offset_; }

 private:
  struct FileCloser {
    void operator()(std::FILE* f) const {
      if (f != nullptr) std::fclose(f);
    }
  };
  /// The Chunk being filled: its uncompressed records, the log-time range of its messages, and per channel the log
  /// time and the offset (in `records`) of each message, for the Message Indexes.
  struct OpenChunk {
    std::string records;
    std::uint64_t start_ns = 0, end_ns = 0;
    std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> index;
  };
  McapWriter(std::unique_ptr<std::FILE, FileCloser> file, std::string path, McapWriterOptions options)
      : file_(std::move(file)), path_(std::move(path)), options_(std::move(options)) {}
  Status put(const std::string& bytes);
  [[nodiscard]] bool chunked() const { return !options_.compression.empty(); }
  /// Writes the open Chunk (if it has records) and its Message Indexes, and keeps its Chunk Index for the summary.
  Status write_chunk();

  std::unique_ptr<std::FILE, FileCloser> file_;
  std::string path_;
  McapWriterOptions options_;
  OpenChunk chunk_;
  std::string chunk_indexes_;  ///< the Chunk Index records of the Chunks written, for the summary
  std::uint32_t chunk_count_ = 0;
  std::uint64_t offset_ = 0;
  std::vector<McapSchema> schemas_;
  std::vector<McapChannel> channels_;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
  std::uint64_t message_count_ = 0;
  std::uint64_t first_log_ns_ = 0, last_log_ns_ = 0;
  bool closed_ = false;
};

/// Everything a recording holds (McapReader).
struct McapContent {
  std::map<std::uint16_t, McapSchema> schemas;
  std::map<std::uint16_t, McapChannel> channels;
  std::vector<McapMessage> messages;
  bool complete = false;  ///< the Footer and the closing magic were there
};

/// Reads a recording (see above). A file cut short is an Error naming the byte offset of the cut; read_mcap_partial
/// returns what came before it instead, with `complete` false. A file cut inside a Chunk: the messages of the Chunks
/// before it, and those of the cut Chunk that the zstd blocks before the cut hold whole; `problem` names the Chunk's
/// byte and the cut's. A corrupt Chunk is an Error in both.
Result<McapContent> read_mcap(const std::string& path);
Result<McapContent> read_mcap_partial(const std::string& path, std::string* problem);

}  // namespace canyon::io
