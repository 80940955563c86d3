#pragma once
// Framing of GNSS byte streams: RTCM 3 frames, u-blox UBX packets and NMEA 0183 sentences, alone or interleaved
// (a u-blox receiver's port carries all three), with resynchronisation.
//
// Bytes arrive in reads of any size (a frame may be split across reads); next() returns each complete packet whose
// check passes, in stream order. Anything else is skipped and counted:
//  - bytes outside any packet (garbage, a stream joined mid-frame);
//  - packets whose CRC-24Q (RTCM 3), Fletcher checksum (UBX) or '*hh' checksum (NMEA) fails. After a failed check
//    the framer resumes at the byte after the failed packet's first byte, so a real frame hidden inside a false
//    start (a 0xD3 byte in garbage announcing 1000 bytes) is still found;
//  - after finish(), a packet cut short by the end of the stream (the first one is counted as truncated; the framer
//    still looks for packets in the bytes after its start).
// The first kMaxReportedProblems problems are kept as text with their byte offset in the stream.
//
// RTCM 3 (RTCM 10403.3 section 4): 0xD3, 6 reserved bits (0), 10-bit length, payload, CRC-24Q over all before it.
// UBX: 0xB5 0x62, class, id, 16-bit little-endian length, payload, 8-bit Fletcher checksum (CK_A, CK_B) over class
// to payload. NMEA: '$', printable ASCII up to '*hh' (XOR of the characters between '$' and '*'), CR LF; at most
// kMaxNmeaLength characters.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace canyon::io {

enum class Protocol : std::uint8_t { Rtcm3, Ubx, Nmea };

/// One packet: its bytes (valid until the next call to push(), next() or finish()) and where it started.
struct Packet {
  Protocol protocol = Protocol::Rtcm3;
  std::span<const std::uint8_t> bytes;  ///< the whole packet: header, payload and check
  std::uint64_t offset = 0;             ///< byte offset of its first byte in the stream

  /// RTCM 3: message number (first 12 bits of the payload), 0 if the payload is shorter.
  [[nodiscard]] int rtcm3_message_number() const;
  /// RTCM 3 payload (without the 3-byte header and the CRC); UBX payload (without header and checksum).
  [[nodiscard]] std::span<const std::uint8_t> payload() const;
  /// UBX class and id.
  [[nodiscard]] std::uint8_t ubx_class() const { return bytes.size() > 2 ? bytes[2] : 0; }
  [[nodiscard]] std::uint8_t ubx_id() const { return bytes.size() > 3 ? bytes[3] : 0; }
};

struct FramerStats {
  std::uint64_t bytes = 0;         ///< bytes pushed
  std::uint64_t rtcm3_frames = 0;  ///< good frames returned
  std::uint64_t ubx_packets = 0;
  std::uint64_t nmea_sentences = 0;
  std::uint64_t rtcm3_bad_crc = 0;  ///< frames whose CRC failed
  std::uint64_t ubx_bad_checksum = 0;
  std::uint64_t nmea_bad_checksum = 0;
  std::uint64_t garbage_bytes = 0;  ///< bytes skipped outside any good packet (failed packets' bytes included)
  std::uint64_t truncated = 0;      ///< a packet cut short by the end of the stream (finish())

  /// Packets that failed their check, and the truncated one.
  [[nodiscard]] std::uint64_t bad_packets() const {
    return rtcm3_bad_crc + ubx_bad_checksum + nmea_bad_checksum + truncated;
  }
};

class StreamFramer {
 public:
  struct Options {
    bool rtcm3 = true;
    bool ubx = true;
    bool nmea = true;
    std::size_t max_ubx_payload = 8192;  ///< longer UBX lengths are taken as a false start (bytes)
  };
  static constexpr std::size_t kMaxNmeaLength = 120;  ///< NMEA allows 82; u-blox proprietary sentences are longer
  static constexpr std::size_t kMaxReportedProblems = 20;

  StreamFramer() : StreamFramer(Options{}) {}
  explicit StreamFramer(Options options) : options_(options) {}

  /// Appends bytes read from the stream.
  void push(std::span<const std::uint8_t> bytes);
  /// The next complete, checked packet; nullopt when more bytes are needed.
  std::optional<Packet> next();
  /// End of the stream: next() no longer waits for bytes. Call next() until nullopt to drain what is left; a packet
  /// cut short is counted as truncated and the rest of the bytes are scanned for packets.
  void finish();

  [[nodiscard]] const FramerStats& stats() const { return stats_; }
  /// "byte N: what" for the first kMaxReportedProblems problems (bad checks, truncation).
  [[nodiscard]] const std::vector<std::string>& problems() const { return problems_; }

 private:
  enum class Candidate { Good, Bad, NeedMore, NotAStart };
  Candidate try_rtcm3(std::size_t& length);
  Candidate try_ubx(std::size_t& length);
  Candidate try_nmea(std::size_t& length);
  void problem(std::uint64_t offset, const std::string& what);
  void drop(std::size_t n);

  Options options_;
  std::vector<std::uint8_t> buffer_;
  std::size_t pos_ = 0;           // first unread byte of buffer_
  std::uint64_t consumed_ = 0;    // stream offset of buffer_[pos_]
  std::size_t pending_skip_ = 0;  // bytes of the packet returned last, dropped on the next call
  bool finished_ = false;
  bool truncation_reported_ = false;
  FramerStats stats_;
  std::vector<std::string> problems_;
};

}  // namespace canyon::io
