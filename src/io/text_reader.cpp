#include "canyon/io/text_reader.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstring>

#include <sys/stat.h>
#include <zlib.h>

namespace canyon::io {

struct TextReader::Impl {
  gzFile file = nullptr;
  ~Impl() {
    if (file != nullptr) gzclose(file);
  }
};

TextReader::TextReader(std::unique_ptr<Impl> impl, std::string path) : impl_(std::move(impl)), path_(std::move(path)) {}
TextReader::TextReader(TextReader&&) noexcept = default;
TextReader& TextReader::operator=(TextReader&&) noexcept = default;
TextReader::~TextReader() = default;

Result<TextReader> TextReader::open(const std::string& path) {
  // gzopen reads plain files transparently, so one code path serves both.
  auto impl = std::make_unique<Impl>();
  impl->file = gzopen(path.c_str(), "rb");
  if (impl->file == nullptr) {
    return Error{std::string("cannot open file: ") + std::strerror(errno), path, 0};
  }
  gzbuffer(impl->file, 1 << 17);
  TextReader reader(std::move(impl), path);
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0 && info.st_size > 0)
    reader.file_size_ = static_cast<std::uint64_t>(info.st_size);
  return reader;
}

double TextReader::fraction_read() const {
  if (file_size_ == 0 || impl_ == nullptr || impl_->file == nullptr) return 0.0;
  if (ended_) return 1.0;
  const auto offset = gzoffset(impl_->file);
  if (offset <= 0) return 0.0;
  return std::min(1.0, static_cast<double>(offset) / static_cast<double>(file_size_));
}

bool TextReader::fill() {
  if (eof_) return false;
  buffer_.erase(0, buffer_pos_);
  buffer_pos_ = 0;
  constexpr std::size_t kChunk = 1 << 16;
  const std::size_t old_size = buffer_.size();
  buffer_.resize(old_size + kChunk);
  const int n = gzread(impl_->file, buffer_.data() + old_size, static_cast<unsigned>(kChunk));
  if (n < 0) {
    int code = 0;
    read_error_ = std::string("read error: ") + gzerror(impl_->file, &code);
    buffer_.resize(old_size);
    eof_ = true;
    return false;
  }
  buffer_.resize(old_size + static_cast<std::size_t>(n));
  if (n == 0) {
    eof_ = true;
    // A gzip stream cut short reads as a clean end in zlib; gzerror tells the difference.
    int code = Z_OK;
    const char* message = gzerror(impl_->file, &code);
    if (code != Z_OK && code != Z_STREAM_END) {
      read_error_ = std::string("read error: ") + message;
    } else if (gzdirect(impl_->file) == 0 && !gzeof(impl_->file)) {
      read_error_ = "read error: compressed stream ended unexpectedly";
    }
    return false;
  }
  return true;
}

std::optional<std::string_view> TextReader::next_line() {
  if (pushed_back_) {
    pushed_back_ = false;
    ++line_number_;
    return std::string_view(line_);
  }
  for (;;) {
    const std::size_t newline = buffer_.find('\n', buffer_pos_);
    if (newline != std::string::npos) {
      line_.assign(buffer_, buffer_pos_, newline - buffer_pos_);
      buffer_pos_ = newline + 1;
      break;
    }
    if (!fill()) {
      if (buffer_pos_ >= buffer_.size()) {
        ended_ = true;
        return std::nullopt;
      }
      line_.assign(buffer_, buffer_pos_, std::string::npos);  // last line without a newline
      buffer_pos_ = buffer_.size();
      line_cut_ = read_error_.has_value();
      break;
    }
  }
  if (!line_.empty() && line_.back() == '\r') line_.pop_back();
  ++line_number_;
  return std::string_view(line_);
}

void TextReader::unread_line() {
  pushed_back_ = true;
  --line_number_;
}

std::string_view column(std::string_view line, std::size_t start, std::size_t width) {
  if (start >= line.size()) return {};
  return line.substr(start, std::min(width, line.size() - start));
}

namespace {
// The blanks of text files; inline rather than std::isspace, a library call per character (hot in RINEX parsing).
constexpr bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}
}  // namespace

std::string_view trim(std::string_view text) {
  while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
  return text;
}

namespace {

constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                             1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
constexpr std::uint64_t kMaxExactMantissa = std::uint64_t{1} << 53;

/// Exact fast path for the numbers RINEX is made of: [+-]digits[.digits][(E|D)[+-]digits]. When the digits form an
/// integer below 2^53 and the decimal scale is a power of ten that double holds exactly (<= 1e22), the value is one
/// IEEE division or multiplication of exact operands, hence correctly rounded: the same result as from_chars.
/// nullopt when the text is not of that form or not in that range (the caller falls back to from_chars).
std::optional<double> parse_simple_decimal(std::string_view text) {
  std::size_t i = 0;
  const bool negative = text[0] == '-';
  if (text[0] == '-' || text[0] == '+') ++i;
  std::uint64_t mantissa = 0;
  int fraction_digits = 0;
  int digits = 0;
  bool dot = false;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c >= '0' && c <= '9') {
      if (++digits > 18) return std::nullopt;
      mantissa = mantissa * 10 + static_cast<std::uint64_t>(c - '0');
      if (dot) ++fraction_digits;
    } else if (c == '.' && !dot) {
      dot = true;
    } else {
      break;
    }
  }
  if (digits == 0 || mantissa >= kMaxExactMantissa) return std::nullopt;
  int exponent = 0;
  if (i < text.size()) {
    if (text[i] != 'E' && text[i] != 'e' && text[i] != 'D' && text[i] != 'd') return std::nullopt;
    ++i;
    bool exponent_negative = false;
    if (i < text.size() && (text[i] == '-' || text[i] == '+')) exponent_negative = text[i++] == '-';
    if (i == text.size() || text.size() - i > 3) return std::nullopt;
    for (; i < text.size(); ++i) {
      if (text[i] < '0' || text[i] > '9') return std::nullopt;
      exponent = exponent * 10 + (text[i] - '0');
    }
    if (exponent_negative) exponent = -exponent;
  }
  const int scale = exponent - fraction_digits;
  double value = static_cast<double>(mantissa);
  if (scale < 0) {
    if (-scale > 22) return std::nullopt;
    value /= kPow10[-scale];
  } else if (scale > 0) {
    // m 10^scale is an integer; if the rounded product is below 2^53 the exact one is too, so it is exact.
    if (scale > 22) return std::nullopt;
    value *= kPow10[scale];
    if (value >= static_cast<double>(kMaxExactMantissa)) return std::nullopt;
  }
  return negative ? -value : value;
}

/// One pass over the commonest form, [spaces][+-]digits[.digits][spaces] with at most 15 digits (every RINEX
/// observation value): Blank, a Value computed exactly as parse_simple_decimal() does (an integer mantissa below
/// 2^53 divided by a power of ten, correctly rounded), or Other (any other form, for the general path).
struct PlainDecimal {
  enum class Kind { Blank, Value, Other };
  Kind kind = Kind::Other;
  double value = 0.0;
};

PlainDecimal parse_plain_decimal(std::string_view text) {
  const char* p = text.data();
  const char* const end = p + text.size();
  while (p != end && *p == ' ') ++p;
  if (p == end) return {PlainDecimal::Kind::Blank, 0.0};
  const bool negative = *p == '-';
  if (*p == '-' || *p == '+') ++p;
  std::uint64_t mantissa = 0;
  int digits = 0;
  int fraction_digits = 0;
  bool dot = false;
  for (; p != end; ++p) {
    const char c = *p;
    if (c >= '0' && c <= '9') {
      mantissa = mantissa * 10 + static_cast<std::uint64_t>(c - '0');
      ++digits;
      fraction_digits += dot ? 1 : 0;
    } else if (c == '.' && !dot) {
      dot = true;
    } else {
      break;
    }
  }
  while (p != end && *p == ' ') ++p;
  constexpr int kMaxPlainDigits = 15;  // mantissa < 10^15 < 2^53: exact
  if (p != end || digits == 0 || digits > kMaxPlainDigits) return {};
  double value = static_cast<double>(mantissa);
  if (fraction_digits > 0) value /= kPow10[fraction_digits];
  return {PlainDecimal::Kind::Value, negative ? -value : value};
}

}  // namespace

std::optional<double> parse_double(std::string_view field, std::optional<double> blank_value) {
  const PlainDecimal plain = parse_plain_decimal(field);
  if (plain.kind == PlainDecimal::Kind::Value) return plain.value;
  if (plain.kind == PlainDecimal::Kind::Blank) return blank_value;
  field = trim(field);
  if (field.empty()) return blank_value;
  if (const auto fast = parse_simple_decimal(field)) return fast;
  char buffer[64] = {};
  if (field.size() >= sizeof buffer) return std::nullopt;
  std::size_t n = 0;
  for (const char c : field) {
    buffer[n++] = (c == 'D' || c == 'd') ? 'E' : c;
  }
  double value = 0.0;
  const char* begin = buffer;
  if (*begin == '+') ++begin;  // from_chars rejects a leading '+'
  const auto [end, ec] = std::from_chars(begin, buffer + n, value);
  if (ec != std::errc{} || end != buffer + n) return std::nullopt;
  return value;
}

std::optional<int> parse_int(std::string_view field, std::optional<int> blank_value) {
  field = trim(field);
  if (field.empty()) return blank_value;
  if (field.front() == '+') field.remove_prefix(1);
  int value = 0;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (ec != std::errc{} || end != field.data() + field.size()) return std::nullopt;
  return value;
}

}  // namespace canyon::io
