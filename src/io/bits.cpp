// CRC-24Q (see bits.hpp), slicing by eight: eight table lookups per eight bytes instead of eight dependent ones.

#include "canyon/io/bits.hpp"

#include <array>

namespace canyon::io {
namespace {

constexpr std::uint32_t kCrc24qPolynomial = 0x1864CFB;

using Tables = std::array<std::array<std::uint32_t, 256>, 8>;

// tables[0][b]: CRC of byte b followed by nothing; tables[k][b]: of byte b followed by k zero bytes.
constexpr Tables make_crc24q_tables() {
  Tables t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t crc = i << 16;
    for (int bit = 0; bit < 8; ++bit) {
      crc <<= 1;
      if ((crc & 0x1000000) != 0) crc ^= kCrc24qPolynomial;
    }
    t[0][i] = crc & 0xFFFFFF;
  }
  for (std::size_t k = 1; k < 8; ++k) {
    for (std::uint32_t i = 0; i < 256; ++i) {
      const std::uint32_t prev = t[k - 1][i];
      t[k][i] = ((prev << 8) & 0xFFFFFF) ^ t[0][(prev >> 16) & 0xFF];
    }
  }
  return t;
}

constexpr Tables kTables = make_crc24q_tables();

}  // namespace

std::uint32_t crc24q(std::span<const std::uint8_t> data) {
  std::uint32_t crc = 0;
  const std::uint8_t* p = data.data();
  std::size_t n = data.size();
  // Eight bytes at a time: the 24-bit CRC is folded into the first three.
  while (n >= 8) {
    const std::uint32_t b0 = p[0] ^ ((crc >> 16) & 0xFF);
    const std::uint32_t b1 = p[1] ^ ((crc >> 8) & 0xFF);
    const std::uint32_t b2 = p[2] ^ (crc & 0xFF);
    crc = kTables[7][b0] ^ kTables[6][b1] ^ kTables[5][b2] ^ kTables[4][p[3]] ^ kTables[3][p[4]] ^ kTables[2][p[5]] ^
          kTables[1][p[6]] ^ kTables[0][p[7]];
    p += 8;
    n -= 8;
  }
  for (; n > 0; --n, ++p) crc = ((crc << 8) & 0xFFFFFF) ^ kTables[0][((crc >> 16) ^ *p) & 0xFF];
  return crc;
}

}  // namespace canyon::io
