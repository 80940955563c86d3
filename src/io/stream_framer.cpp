// Framing of RTCM 3 / UBX / NMEA byte streams (see stream_framer.hpp).

#include "canyon/io/stream_framer.hpp"

#include <cstdio>

#include "canyon/io/bits.hpp"

namespace canyon::io {
namespace {

constexpr std::uint8_t kRtcm3Preamble = 0xD3;
constexpr std::uint8_t kUbxSync1 = 0xB5;
constexpr std::uint8_t kUbxSync2 = 0x62;
constexpr std::size_t kRtcm3HeaderBytes = 3;
constexpr std::size_t kRtcm3CrcBytes = 3;
constexpr std::size_t kUbxHeaderBytes = 6;
constexpr std::size_t kUbxChecksumBytes = 2;

int hex_digit(std::uint8_t c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

}  // namespace

int Packet::rtcm3_message_number() const {
  if (protocol != Protocol::Rtcm3 || bytes.size() < kRtcm3HeaderBytes + 2 + kRtcm3CrcBytes) return 0;
  return (bytes[3] << 4) | (bytes[4] >> 4);
}

std::span<const std::uint8_t> Packet::payload() const {
  switch (protocol) {
    case Protocol::Rtcm3:
      if (bytes.size() < kRtcm3HeaderBytes + kRtcm3CrcBytes) return {};
      return bytes.subspan(kRtcm3HeaderBytes, bytes.size() - kRtcm3HeaderBytes - kRtcm3CrcBytes);
    case Protocol::Ubx:
      if (bytes.size() < kUbxHeaderBytes + kUbxChecksumBytes) return {};
      return bytes.subspan(kUbxHeaderBytes, bytes.size() - kUbxHeaderBytes - kUbxChecksumBytes);
    case Protocol::Nmea: return bytes;
  }
  return {};
}

void StreamFramer::drop(std::size_t n) {
  pos_ += n;
  consumed_ += n;
}

void StreamFramer::push(std::span<const std::uint8_t> bytes) {
  drop(pending_skip_);
  pending_skip_ = 0;
  stats_.bytes += bytes.size();
  // Keep the unread tail only; compact when the read part dominates (amortised O(1) per byte).
  if (pos_ > 0 && pos_ >= buffer_.size() / 2) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(pos_));
    pos_ = 0;
  }
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

void StreamFramer::problem(std::uint64_t offset, const std::string& what) {
  if (problems_.size() < kMaxReportedProblems) problems_.push_back("byte " + std::to_string(offset) + ": " + what);
}

StreamFramer::Candidate StreamFramer::try_rtcm3(std::size_t& length) {
  const std::size_t available = buffer_.size() - pos_;
  const std::uint8_t* p = buffer_.data() + pos_;
  if (available < kRtcm3HeaderBytes) return Candidate::NeedMore;
  if ((p[1] & 0xFC) != 0) return Candidate::NotAStart;  // reserved bits must be zero
  const std::size_t payload = (static_cast<std::size_t>(p[1] & 0x03) << 8) | p[2];
  length = kRtcm3HeaderBytes + payload + kRtcm3CrcBytes;
  if (available < length) return Candidate::NeedMore;
  const std::uint32_t crc = crc24q({p, kRtcm3HeaderBytes + payload});
  const std::uint8_t* c = p + kRtcm3HeaderBytes + payload;
  const std::uint32_t expected = (std::uint32_t{c[0]} << 16) | (std::uint32_t{c[1]} << 8) | c[2];
  return crc == expected ? Candidate::Good : Candidate::Bad;
}

StreamFramer::Candidate StreamFramer::try_ubx(std::size_t& length) {
  const std::size_t available = buffer_.size() - pos_;
  const std::uint8_t* p = buffer_.data() + pos_;
  if (available < 2) return Candidate::NeedMore;
  if (p[1] != kUbxSync2) return Candidate::NotAStart;
  if (available < kUbxHeaderBytes) return Candidate::NeedMore;
  const std::size_t payload = p[4] | (static_cast<std::size_t>(p[5]) << 8);
  if (payload > options_.max_ubx_payload) return Candidate::NotAStart;
  length = kUbxHeaderBytes + payload + kUbxChecksumBytes;
  if (available < length) return Candidate::NeedMore;
  std::uint8_t a = 0;
  std::uint8_t b = 0;
  for (std::size_t i = 2; i < kUbxHeaderBytes + payload; ++i) {
    a = static_cast<std::uint8_t>(a + p[i]);
    b = static_cast<std::uint8_t>(b + a);
  }
  return a == p[length - 2] && b == p[length - 1] ? Candidate::Good : Candidate::Bad;
}

StreamFramer::Candidate StreamFramer::try_nmea(std::size_t& length) {
  const std::size_t available = buffer_.size() - pos_;
  const std::uint8_t* p = buffer_.data() + pos_;
  std::uint8_t sum = 0;
  for (std::size_t i = 1; i < kMaxNmeaLength; ++i) {
    if (i >= available) return Candidate::NeedMore;
    const std::uint8_t c = p[i];
    if (c == '*') {
      // '*hh' then CR LF (or LF alone).
      if (i + 3 > available) return Candidate::NeedMore;
      const int high = hex_digit(p[i + 1]);
      const int low = hex_digit(p[i + 2]);
      if (high < 0 || low < 0 || i < 6) return Candidate::NotAStart;
      std::size_t end = i + 3;
      if (end < available && p[end] == '\r') ++end;
      if (end >= available) return Candidate::NeedMore;
      if (p[end] != '\n') return Candidate::NotAStart;
      length = end + 1;
      return sum == ((high << 4) | low) ? Candidate::Good : Candidate::Bad;
    }
    if (c < 0x20 || c > 0x7E || c == '$') return Candidate::NotAStart;
    sum ^= c;
  }
  return Candidate::NotAStart;
}

std::optional<Packet> StreamFramer::next() {
  drop(pending_skip_);
  pending_skip_ = 0;
  while (pos_ < buffer_.size()) {
    const std::uint8_t b = buffer_[pos_];
    Candidate c = Candidate::NotAStart;
    Protocol protocol = Protocol::Rtcm3;
    std::size_t length = 0;
    if (b == kRtcm3Preamble && options_.rtcm3) {
      c = try_rtcm3(length);
    } else if (b == kUbxSync1 && options_.ubx) {
      protocol = Protocol::Ubx;
      c = try_ubx(length);
    } else if (b == '$' && options_.nmea) {
      protocol = Protocol::Nmea;
      c = try_nmea(length);
    }
    if (c == Candidate::NeedMore && finished_) {
      // End of the stream inside a packet: count the first such cut, then look for packets in what is left.
      if (!truncation_reported_ && protocol != Protocol::Nmea) {
        truncation_reported_ = true;
        ++stats_.truncated;
        problem(consumed_, std::string(protocol == Protocol::Rtcm3 ? "RTCM 3 frame" : "UBX packet") +
                               " cut short by the end of the stream (" + std::to_string(buffer_.size() - pos_) +
                               " bytes left)");
      }
      c = Candidate::NotAStart;
    }
    switch (c) {
      case Candidate::Good: {
        Packet packet{protocol, {buffer_.data() + pos_, length}, consumed_};
        pending_skip_ = length;
        if (protocol == Protocol::Rtcm3) ++stats_.rtcm3_frames;
        if (protocol == Protocol::Ubx) ++stats_.ubx_packets;
        if (protocol == Protocol::Nmea) ++stats_.nmea_sentences;
        return packet;
      }
      case Candidate::NeedMore: return std::nullopt;
      case Candidate::Bad: {
        char what[96];
        if (protocol == Protocol::Rtcm3) {
          ++stats_.rtcm3_bad_crc;
          const int number = length >= 8 ? (buffer_[pos_ + 3] << 4) | (buffer_[pos_ + 4] >> 4) : 0;
          std::snprintf(what, sizeof what, "RTCM 3 frame (message %d, %zu bytes) fails its CRC", number, length);
        } else if (protocol == Protocol::Ubx) {
          ++stats_.ubx_bad_checksum;
          std::snprintf(what, sizeof what, "UBX packet (0x%02X 0x%02X, %zu bytes) fails its checksum",
                        buffer_[pos_ + 2], buffer_[pos_ + 3], length);
        } else {
          ++stats_.nmea_bad_checksum;
          std::snprintf(what, sizeof what, "NMEA sentence (%zu bytes) fails its checksum", length);
        }
        problem(consumed_, what);
        ++stats_.garbage_bytes;
        drop(1);
        break;
      }
      case Candidate::NotAStart:
        ++stats_.garbage_bytes;
        drop(1);
        break;
    }
  }
  return std::nullopt;
}

void StreamFramer::finish() {
  finished_ = true;
}

}  // namespace canyon::io
