// Fast number parsing and formatting agree with the C library on the forms RINEX and .pos use.

#include <charconv>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "canyon/io/number_format.hpp"
#include "canyon/io/text_reader.hpp"

namespace canyon::io {
namespace {

double reference_parse(std::string text) {
  for (char& c : text) {
    if (c == 'D') c = 'E';
  }
  return std::strtod(text.c_str(), nullptr);
}

TEST(ParseDouble, FastPathEqualsStrtodBitForBit) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> magnitude(-12.0, 9.0);
  std::uniform_int_distribution<int> sign(0, 1);
  // RINEX observations and navigation records, .pos and CSV files (vio.csv: %.10e, %.12f), padded fields.
  const char* formats[] = {"%14.3f", "%19.12E", "%.12E", "%10.4f", "%g", "%.17g", "%8.1f", "%.10e", "%.12f", " %.6f "};
  int checked = 0;
  for (int i = 0; i < 200000; ++i) {
    const double v = (sign(rng) ? -1.0 : 1.0) * std::pow(10.0, magnitude(rng));
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, formats[i % std::size(formats)], v);
    std::string text = buffer;
    if (i % 3 == 0) {  // Fortran exponent letter as in RINEX navigation files
      const auto e = text.find('E');
      if (e != std::string::npos) text[e] = 'D';
    }
    const auto parsed = parse_double(text);
    ASSERT_TRUE(parsed.has_value()) << text;
    ASSERT_EQ(*parsed, reference_parse(text)) << text;
    ++checked;
  }
  EXPECT_EQ(checked, 200000);
}

TEST(ParseDouble, FormsAndRejects) {
  EXPECT_EQ(*parse_double(" 1.000000000000D+00"), 1.0);
  EXPECT_EQ(*parse_double("-4.19095158577D-09"), -4.19095158577e-09);
  EXPECT_EQ(*parse_double("  21234567.123"), 21234567.123);
  EXPECT_EQ(*parse_double("+5"), 5.0);
  EXPECT_EQ(*parse_double(".5"), 0.5);
  EXPECT_EQ(*parse_double("123456789012345678901234"), 123456789012345678901234.0);  // fallback path
  EXPECT_EQ(*parse_double("   ", 7.0), 7.0);
  EXPECT_FALSE(parse_double("   ").has_value());
  for (const char* bad : {"1.2.3", "12a", "--1", "1E", "1D+", "+", ".", "1 2", "0x10", "nan1"}) {
    EXPECT_FALSE(parse_double(bad).has_value()) << bad;
  }
}

TEST(NumberFormat, MatchesPrintfAwayFromTies) {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> value(-1e6, 1e6);
  for (int i = 0; i < 100000; ++i) {
    const double v = value(rng);
    for (const auto& [width, decimals] : {std::pair{14, 9}, {10, 4}, {8, 4}, {6, 2}, {6, 1}, {10, 3}}) {
      char expected[64];
      std::snprintf(expected, sizeof expected, "%*.*f", width, decimals, v);
      std::string out;
      append_fixed(out, v, width, decimals);
      // A value this close to a decimal tie may round either way; everything else must match exactly.
      const double scaled = std::abs(v) * std::pow(10.0, decimals);
      if (std::abs(scaled - std::floor(scaled) - 0.5) < 1e-6) continue;
      if (std::string(expected) == "-0.0" || std::string(expected).find("-0.") != std::string::npos) {
        if (std::abs(v) * std::pow(10.0, decimals) < 0.5) continue;  // canyon prints 0, not -0
      }
      ASSERT_EQ(out, expected) << v << " " << width << "." << decimals;
    }
  }
}

TEST(NumberFormat, EdgeCases) {
  std::string out;
  append_fixed(out, -0.00001, 8, 4);
  EXPECT_EQ(out, "  0.0000");
  out.clear();
  append_fixed(out, std::nan(""), 6, 2);
  EXPECT_NE(out.find("nan"), std::string::npos);
  out.clear();
  append_fixed(out, 1e16, 5, 1);
  EXPECT_EQ(out, "10000000000000000.0");
  out.clear();
  append_fixed(out, 123456.789, 3, 2);  // wider than the field: no truncation
  EXPECT_EQ(out, "123456.79");
  out.clear();
  append_int(out, -42, 5);
  append_int(out, 7, 3);
  append_int(out, -9223372036854775807LL - 1, 1);
  EXPECT_EQ(out, "  -42  7-9223372036854775808");
}

}  // namespace
}  // namespace canyon::io
