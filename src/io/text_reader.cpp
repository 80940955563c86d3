#include "canyon/io/text_reader.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstring>

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
  return TextReader(std::move(impl), path);
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
      if (buffer_pos_ >= buffer_.size()) return std::nullopt;
      line_.assign(buffer_, buffer_pos_, std::string::npos);  // last line without a newline
      buffer_pos_ = buffer_.size();
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

std::string_view trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.remove_suffix(1);
  return text;
}

std::optional<double> parse_double(std::string_view field, std::optional<double> blank_value) {
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
