// Fixed-point number formatting (see number_format.hpp).

#include "canyon/io/number_format.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>

namespace canyon::io {
namespace {

constexpr double kPow10[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12};

void append_padded(std::string& out, const char* digits, int length, int width) {
  for (int i = length; i < width; ++i) out += ' ';
  out.append(digits, static_cast<std::size_t>(length));
}

}  // namespace

void append_fixed(std::string& out, double value, int width, int decimals) {
  if (decimals < 0 || decimals > 12 || !std::isfinite(value) || std::abs(value) >= 1e15 ||
      std::abs(value) * kPow10[decimals] >= 9e18) {
    char buffer[64];
    const int n = std::snprintf(buffer, sizeof buffer, "%*.*f", width, decimals, value);
    out.append(buffer, static_cast<std::size_t>(n > 0 ? n : 0));
    return;
  }
  const bool negative = std::signbit(value);
  const auto scaled = static_cast<std::uint64_t>(std::llround(std::abs(value) * kPow10[decimals]));
  // Digits from the right: fraction, point, integer part, sign.
  char buffer[32];
  int pos = sizeof buffer;
  std::uint64_t rest = scaled;
  for (int d = 0; d < decimals; ++d) {
    buffer[--pos] = static_cast<char>('0' + rest % 10);
    rest /= 10;
  }
  if (decimals > 0) buffer[--pos] = '.';
  do {
    buffer[--pos] = static_cast<char>('0' + rest % 10);
    rest /= 10;
  } while (rest > 0);
  if (negative && scaled != 0) buffer[--pos] = '-';  // printf prints -0.000 for -0.0001; a plain 0 reads better
  append_padded(out, buffer + pos, static_cast<int>(sizeof buffer) - pos, width);
}

void append_int(std::string& out, long long value, int width) {
  char buffer[24];
  int pos = sizeof buffer;
  const bool negative = value < 0;
  auto rest = negative ? static_cast<unsigned long long>(-(value + 1)) + 1 : static_cast<unsigned long long>(value);
  do {
    buffer[--pos] = static_cast<char>('0' + rest % 10);
    rest /= 10;
  } while (rest > 0);
  if (negative) buffer[--pos] = '-';
  append_padded(out, buffer + pos, static_cast<int>(sizeof buffer) - pos, width);
}

}  // namespace canyon::io
