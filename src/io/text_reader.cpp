#include "canyon/io/text_reader.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstring>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

namespace canyon::io {

// Two sources: a plain regular file is mapped into memory (lines are views into the map: no copy, no read calls);
// anything else (gzip, a pipe, an empty file) is read through zlib, which reads plain data transparently, into a
// buffer of whole lines.
struct TextReader::Impl {
  gzFile file = nullptr;
  const char* map = nullptr;  // the whole file when mapped
  std::size_t map_size = 0;
  long long compressed_offset = 0;  // gzoffset() after the last read, for fraction_read()
  ~Impl() {
    if (file != nullptr) gzclose(file);
    if (map != nullptr) ::munmap(const_cast<char*>(map), map_size);  // NOLINT(cppcoreguidelines-pro-type-const-cast)
  }
};

TextReader::TextReader(std::unique_ptr<Impl> impl, std::string path) : impl_(std::move(impl)), path_(std::move(path)) {}
TextReader::TextReader(TextReader&& other) noexcept {
  *this = std::move(other);
}

TextReader& TextReader::operator=(TextReader&& other) noexcept {
  if (this == &other) return *this;
  // view_ and line_ point into other's buffer_ when it is the source: re-derived from their offsets after the move
  // (a short string's characters move with the object).
  const bool buffered = other.impl_ == nullptr || other.impl_->map == nullptr;
  const std::size_t line_offset =
      other.line_.empty() ? 0 : static_cast<std::size_t>(other.line_.data() - other.view_.data());
  const std::size_t line_size = other.line_.size();
  impl_ = std::move(other.impl_);
  path_ = std::move(other.path_);
  buffer_ = std::move(other.buffer_);
  view_ = buffered ? std::string_view(buffer_) : other.view_;
  view_pos_ = other.view_pos_;
  line_ = view_.substr(std::min(line_offset, view_.size()), line_size);
  pushed_back_ = other.pushed_back_;
  eof_ = other.eof_;
  ended_ = other.ended_;
  line_cut_ = other.line_cut_;
  line_number_ = other.line_number_;
  file_size_ = other.file_size_;
  read_error_ = std::move(other.read_error_);
  other.view_ = {};
  other.line_ = {};
  return *this;
}
TextReader::~TextReader() = default;

namespace {

/// The whole of a plain (not gzip) regular file mapped read-only, or nullptr when it cannot be (then zlib reads it).
const char* map_plain_file(const std::string& path, std::size_t& size) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);  // NOLINT(cppcoreguidelines-pro-type-vararg)
  if (fd < 0) return nullptr;
  struct stat info {};
  const char* map = nullptr;
  if (::fstat(fd, &info) == 0 && S_ISREG(info.st_mode) && info.st_size > 2) {
    size = static_cast<std::size_t>(info.st_size);
    void* p = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (p != MAP_FAILED) {
      map = static_cast<const char*>(p);
      const auto* bytes =
          reinterpret_cast<const unsigned char*>(map);  // NOLINT(cppcoreguidelines-pro-type-reinterpret-cast)
      if (bytes[0] == 0x1f && bytes[1] == 0x8b) {       // gzip magic: decompress instead
        ::munmap(p, size);
        map = nullptr;
      } else {
        // Two calls: the advice values are not flags (MADV_SEQUENTIAL | MADV_WILLNEED is MADV_WILLNEED alone).
        ::madvise(p, size, MADV_SEQUENTIAL);
        ::madvise(p, size, MADV_WILLNEED);
      }
    }
  }
  ::close(fd);
  return map;
}

}  // namespace

Result<TextReader> TextReader::open(const std::string& path) {
  auto impl = std::make_unique<Impl>();
  std::size_t size = 0;
  impl->map = map_plain_file(path, size);
  if (impl->map != nullptr) {
    impl->map_size = size;
    TextReader reader(std::move(impl), path);
    reader.view_ = std::string_view(reader.impl_->map, size);
    reader.eof_ = true;  // everything is in view_ already
    reader.file_size_ = size;
    return reader;
  }
  impl->file = gzopen(path.c_str(), "rb");
  if (impl->file == nullptr) {
    return Error{std::string("cannot open file: ") + std::strerror(errno), path, 0};
  }
  gzbuffer(impl->file, 1 << 17);
  TextReader reader(std::move(impl), path);
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0 && info.st_size > 0) {
    reader.file_size_ = static_cast<std::uint64_t>(info.st_size);
  }
  return reader;
}

double TextReader::fraction_read() const {
  if (ended_) return 1.0;
  if (file_size_ == 0 || impl_ == nullptr) return 0.0;
  const double done =
      impl_->map != nullptr ? static_cast<double>(view_pos_) : static_cast<double>(impl_->compressed_offset);
  return std::clamp(done / static_cast<double>(file_size_), 0.0, 1.0);
}

bool TextReader::fill() {
  if (eof_) return false;
  buffer_.erase(0, view_pos_);
  view_pos_ = 0;
  constexpr std::size_t kChunk = 1 << 16;
  const std::size_t old_size = buffer_.size();
  buffer_.resize(old_size + kChunk);
  const int n = gzread(impl_->file, buffer_.data() + old_size, static_cast<unsigned>(kChunk));
  impl_->compressed_offset = gzoffset(impl_->file);
  if (n < 0) {
    int code = 0;
    read_error_ = std::string("read error: ") + gzerror(impl_->file, &code);
    buffer_.resize(old_size);
    view_ = buffer_;
    eof_ = true;
    return false;
  }
  buffer_.resize(old_size + static_cast<std::size_t>(n));
  view_ = buffer_;
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
    return line_;
  }
  for (;;) {
    const std::size_t newline = view_.find('\n', view_pos_);
    if (newline != std::string_view::npos) {
      line_ = view_.substr(view_pos_, newline - view_pos_);
      view_pos_ = newline + 1;
      break;
    }
    if (!fill()) {
      if (view_pos_ >= view_.size()) {
        ended_ = true;
        return std::nullopt;
      }
      line_ = view_.substr(view_pos_);  // last line without a newline
      view_pos_ = view_.size();
      line_cut_ = read_error_.has_value();
      break;
    }
  }
  if (!line_.empty() && line_.back() == '\r') line_.remove_suffix(1);
  ++line_number_;
  return line_;
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

/// A field read in one pass when it has the form of every RINEX and CSV number canyon meets,
/// [spaces][+-]digits[.digits][(E|e|D|d)[+-]d[d[d]]][spaces]: Blank, an exact Value, or Other (any other form or
/// range, for from_chars). When the digits form an integer below 2^53 and the decimal scale is a power of ten that a
/// double holds exactly (<= 1e22), the value is one IEEE division or multiplication of exact operands, hence
/// correctly rounded: the result from_chars gives.
struct FastDecimal {
  enum class Kind { Blank, Value, Other };
  Kind kind = Kind::Other;
  double value = 0.0;
};

FastDecimal parse_fast_decimal(std::string_view text) {
  constexpr FastDecimal kOther{};
  const char* p = text.data();
  const char* const end = p + text.size();
  while (p != end && *p == ' ') ++p;
  if (p == end) return {FastDecimal::Kind::Blank, 0.0};
  const bool negative = *p == '-';
  if (*p == '-' || *p == '+') ++p;
  std::uint64_t mantissa = 0;
  int digits = 0;
  int fraction_digits = 0;
  bool dot = false;
  for (; p != end; ++p) {
    const char c = *p;
    if (c >= '0' && c <= '9') {
      if (++digits > 18) return kOther;  // the mantissa could overflow; beyond the exact range anyway
      mantissa = mantissa * 10 + static_cast<std::uint64_t>(c - '0');
      fraction_digits += dot ? 1 : 0;
    } else if (c == '.' && !dot) {
      dot = true;
    } else {
      break;
    }
  }
  int exponent = 0;
  if (p != end && (*p == 'E' || *p == 'e' || *p == 'D' || *p == 'd')) {
    ++p;
    const bool exponent_negative = p != end && *p == '-';
    if (p != end && (*p == '-' || *p == '+')) ++p;
    int exponent_digits = 0;
    for (; p != end && *p >= '0' && *p <= '9'; ++p) {
      if (++exponent_digits > 3) return kOther;
      exponent = exponent * 10 + (*p - '0');
    }
    if (exponent_digits == 0) return kOther;
    if (exponent_negative) exponent = -exponent;
  }
  while (p != end && *p == ' ') ++p;
  if (p != end || digits == 0 || mantissa >= kMaxExactMantissa) return kOther;
  const int scale = exponent - fraction_digits;
  double value = static_cast<double>(mantissa);
  if (scale < 0) {
    if (-scale > 22) return kOther;
    value /= kPow10[-scale];
  } else if (scale > 0) {
    // m 10^scale is an integer; if the rounded product is below 2^53 the exact one is too, so it is exact.
    if (scale > 22) return kOther;
    value *= kPow10[scale];
    if (value >= static_cast<double>(kMaxExactMantissa)) return kOther;
  }
  return {FastDecimal::Kind::Value, negative ? -value : value};
}

}  // namespace

std::optional<double> parse_double(std::string_view field, std::optional<double> blank_value) {
  const FastDecimal fast = parse_fast_decimal(field);
  if (fast.kind == FastDecimal::Kind::Value) return fast.value;
  if (fast.kind == FastDecimal::Kind::Blank) return blank_value;
  field = trim(field);
  if (field.empty()) return blank_value;
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
