// CRC-24Q (see bits.hpp).

#include "canyon/io/bits.hpp"

#include <array>

namespace canyon::io {
namespace {

constexpr std::uint32_t kCrc24qPolynomial = 0x1864CFB;

constexpr std::array<std::uint32_t, 256> make_crc24q_table() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t crc = i << 16;
    for (int bit = 0; bit < 8; ++bit) {
      crc <<= 1;
      if ((crc & 0x1000000) != 0) crc ^= kCrc24qPolynomial;
    }
    table[i] = crc & 0xFFFFFF;
  }
  return table;
}

constexpr std::array<std::uint32_t, 256> kCrc24qTable = make_crc24q_table();

}  // namespace

std::uint32_t crc24q(std::span<const std::uint8_t> data) {
  std::uint32_t crc = 0;
  for (const std::uint8_t byte : data) {
    crc = ((crc << 8) & 0xFFFFFF) ^ kCrc24qTable[((crc >> 16) ^ byte) & 0xFF];
  }
  return crc;
}

}  // namespace canyon::io
