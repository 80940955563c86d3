#pragma once
// Bit fields of binary GNSS messages (RTCM 3, navigation words): most significant bit first, as both RTCM 10403.3
// and the satellite ICDs number them, and the CRC-24Q of RTCM 3 and Galileo I/NAV.
//
// BitReader does not check bounds per field: a decoder checks once that the message holds every bit it will read
// (bits_left()), then reads without branches. Reading past the end is a programmer error (assertion).

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace canyon::io {

/// CRC-24Q (polynomial 0x1864CFB, initial value 0, no reflection) of `data`: the RTCM 3 frame check.
[[nodiscard]] std::uint32_t crc24q(std::span<const std::uint8_t> data);

/// Unsigned field of `n` bits (n <= 64) at bit `pos` of `data`; the caller guarantees pos + n <= 8 * size.
[[nodiscard]] inline std::uint64_t get_bits(const std::uint8_t* data, std::size_t size, std::size_t pos, unsigned n) {
  assert(n <= 64 && pos + n <= 8 * size);
  if (n == 0) return 0;
  if (n > 56) {
    const std::uint64_t high = get_bits(data, size, pos, n - 32);
    return (high << 32) | get_bits(data, size, pos + n - 32, 32);
  }
  const std::size_t first = pos >> 3;
  const unsigned skip = static_cast<unsigned>(pos & 7);
  const std::size_t last = (pos + n - 1) >> 3;  // inclusive
  std::uint64_t word = 0;
  if (first + 8 <= size) {
    // Eight bytes, big-endian, whatever n is: one load (the compiler merges the shifts) and two shifts.
    for (std::size_t i = 0; i < 8; ++i) word = (word << 8) | data[first + i];
  } else {
    for (std::size_t i = first; i <= last; ++i) word = (word << 8) | data[i];
    word <<= 8 * (8 - (last - first + 1));
  }
  return (word << skip) >> (64 - n);
}

/// The value of an `n`-bit two's complement pattern (2 <= n <= 64).
[[nodiscard]] inline std::int64_t twos_complement_value(std::uint64_t u, unsigned n) {
  if (n == 64) return static_cast<std::int64_t>(u);
  const std::uint64_t sign = std::uint64_t{1} << (n - 1);
  return static_cast<std::int64_t>(u ^ sign) - static_cast<std::int64_t>(sign);
}

/// The value of an `n`-bit sign-magnitude pattern (GLONASS): the first bit is the sign.
[[nodiscard]] inline std::int64_t sign_magnitude_value(std::uint64_t u, unsigned n) {
  const std::uint64_t magnitude = u & ((std::uint64_t{1} << (n - 1)) - 1);
  return (u >> (n - 1)) != 0 ? -static_cast<std::int64_t>(magnitude) : static_cast<std::int64_t>(magnitude);
}

/// Two's complement field of `n` bits (2 <= n <= 64).
[[nodiscard]] inline std::int64_t get_bits_signed(const std::uint8_t* data, std::size_t size, std::size_t pos,
                                                  unsigned n) {
  return twos_complement_value(get_bits(data, size, pos, n), n);
}

/// Sign-magnitude field of `n` bits (GLONASS): the first bit is the sign.
[[nodiscard]] inline std::int64_t get_bits_sign_magnitude(const std::uint8_t* data, std::size_t size, std::size_t pos,
                                                          unsigned n) {
  return sign_magnitude_value(get_bits(data, size, pos, n), n);
}

/// The `n`-bit sign-magnitude pattern of `value` (GLONASS): sign bit, then |value| in n - 1 bits (not masked).
[[nodiscard]] inline std::uint64_t sign_magnitude_bits(std::int64_t value, unsigned n) {
  const std::uint64_t magnitude = static_cast<std::uint64_t>(value < 0 ? -value : value);
  return ((value < 0 ? std::uint64_t{1} : 0) << (n - 1)) | magnitude;
}

/// Sequential reader over a message.
class BitReader {
 public:
  explicit BitReader(std::span<const std::uint8_t> data, std::size_t pos = 0) : data_(data), pos_(pos) {}

  [[nodiscard]] std::size_t position() const { return pos_; }
  [[nodiscard]] std::size_t bits_left() const { return 8 * data_.size() - pos_; }
  void skip(std::size_t n) {
    assert(n <= bits_left());
    pos_ += n;
  }

  std::uint64_t u(unsigned n) {
    const std::uint64_t v = get_bits(data_.data(), data_.size(), pos_, n);
    pos_ += n;
    return v;
  }
  std::uint32_t u32(unsigned n) {
    assert(n <= 32);
    return static_cast<std::uint32_t>(u(n));
  }
  std::int64_t s(unsigned n) {
    const std::int64_t v = get_bits_signed(data_.data(), data_.size(), pos_, n);
    pos_ += n;
    return v;
  }
  std::int64_t sm(unsigned n) {
    const std::int64_t v = get_bits_sign_magnitude(data_.data(), data_.size(), pos_, n);
    pos_ += n;
    return v;
  }

 private:
  std::span<const std::uint8_t> data_;
  std::size_t pos_;
};

/// Sequential writer: appends fields to a byte vector (the last byte is zero-padded). Bits collect in a 64-bit
/// accumulator and go to the vector a byte at a time; the vector holds every completed byte, and the partial last
/// byte once flush() or the destructor ran (bits() and position() count all bits at any time).
class BitWriter {
 public:
  explicit BitWriter(std::vector<std::uint8_t>& out) : out_(out), start_bits_(8 * out.size()) {}
  ~BitWriter() { flush(); }
  BitWriter(const BitWriter&) = delete;
  BitWriter& operator=(const BitWriter&) = delete;

  /// Appends the low `n` bits of `value` (n <= 64).
  void u(std::uint64_t value, unsigned n) {
    assert(n <= 64);
    if (n > 32) {
      u(value >> 32, n - 32);
      n = 32;
    }
    value &= n == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << n) - 1;
    acc_ = (acc_ << n) | value;  // acc_ holds fewer than 8 pending bits, so n <= 32 always fits
    pending_ += n;
    bits_ += n;
    while (pending_ >= 8) {
      pending_ -= 8;
      out_.push_back(static_cast<std::uint8_t>(acc_ >> pending_));
    }
  }
  /// Two's complement; the caller checks the range.
  void s(std::int64_t value, unsigned n) { u(static_cast<std::uint64_t>(value), n); }
  /// Sign-magnitude (GLONASS): sign bit, then |value| in n - 1 bits.
  void sm(std::int64_t value, unsigned n) { u(sign_magnitude_bits(value, n), n); }
  /// Writes the partial last byte (zero-padded) into the vector; further writes start a new byte.
  void flush() {
    if (pending_ > 0) {
      out_.push_back(static_cast<std::uint8_t>(acc_ << (8 - pending_)));
      bits_ += 8 - pending_;
      pending_ = 0;
    }
  }
  /// Bits written by this writer.
  [[nodiscard]] std::size_t bits() const { return bits_; }
  /// Absolute bit position in the vector.
  [[nodiscard]] std::size_t position() const { return start_bits_ + bits_; }

 private:
  std::vector<std::uint8_t>& out_;
  std::size_t start_bits_;
  std::size_t bits_ = 0;
  std::uint64_t acc_ = 0;
  unsigned pending_ = 0;  // bits in acc_ not yet in out_ (< 8)
};

/// Writer into a buffer the caller has sized to hold every bit it will write (hot paths: MSM encoding). Whole
/// 32-bit words are stored as they fill; flush() stores the rest, the last byte zero-padded.
class FixedBitWriter {
 public:
  explicit FixedBitWriter(std::uint8_t* data) : p_(data) {}

  void u(std::uint64_t value, unsigned n) {
    assert(n <= 64);
    if (n > 32) {
      put(value >> 32, n - 32);
      n = 32;
    }
    put(value, n);
  }
  void s(std::int64_t value, unsigned n) { u(static_cast<std::uint64_t>(value), n); }
  void flush() {
    while (pending_ >= 8) {
      pending_ -= 8;
      *p_++ = static_cast<std::uint8_t>(acc_ >> pending_);
    }
    if (pending_ > 0) *p_++ = static_cast<std::uint8_t>(acc_ << (8 - pending_));
    pending_ = 0;
  }

 private:
  /// At most 32 bits (not recursive, so that it inlines).
  void put(std::uint64_t value, unsigned n) {
    value &= (std::uint64_t{1} << n) - 1;
    acc_ = (acc_ << n) | value;  // fewer than 32 pending bits + at most 32 new ones
    pending_ += n;
    if (pending_ >= 32) {
      pending_ -= 32;
      const auto word = static_cast<std::uint32_t>(acc_ >> pending_);
      p_[0] = static_cast<std::uint8_t>(word >> 24);
      p_[1] = static_cast<std::uint8_t>(word >> 16);
      p_[2] = static_cast<std::uint8_t>(word >> 8);
      p_[3] = static_cast<std::uint8_t>(word);
      p_ += 4;
    }
  }

  std::uint8_t* p_;
  std::uint64_t acc_ = 0;
  unsigned pending_ = 0;
};

}  // namespace canyon::io
