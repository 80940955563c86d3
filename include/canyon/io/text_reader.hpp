#pragma once
// Line-oriented reading of text files, plain or gzip-compressed (detected from the content, not the name), with
// the line number kept for error messages, and fixed-column field parsing as RINEX needs it.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "canyon/core/result.hpp"

namespace canyon::io {

class TextReader {
 public:
  /// Opens `path`; a gzip file is decompressed on the fly. Error if it cannot be opened.
  static Result<TextReader> open(const std::string& path);
  TextReader(TextReader&&) noexcept;
  TextReader& operator=(TextReader&&) noexcept;
  ~TextReader();

  /// Next line without its end-of-line characters (LF or CRLF); nullopt at end of file. A read error
  /// (e.g. a truncated gzip stream) is reported by error() after next_line() returns nullopt. The view is valid until
  /// the next call.
  std::optional<std::string_view> next_line();
  /// Pushes the last line back so the next call to next_line() returns it again (one line only).
  void unread_line();
  /// 1-based number of the line last returned.
  [[nodiscard]] int line_number() const { return line_number_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  /// Read error, if reading stopped because of one rather than at the end of the file.
  [[nodiscard]] const std::optional<std::string>& read_error() const { return read_error_; }
  /// Whether next_line() has returned nullopt: nothing more to read (see read_error() for why).
  [[nodiscard]] bool ended() const { return ended_; }
  /// Whether the last line consumed (returned and not pushed back) is the unterminated tail that a read error left
  /// behind: a line cut short, e.g. by a truncated gzip stream.
  [[nodiscard]] bool line_cut() const { return line_cut_ && !pushed_back_; }
  /// Fraction of the file read so far, 0..1 (of the compressed size for gzip); 0 if the size is unknown. For
  /// progress reports: it moves in steps of the read buffer.
  [[nodiscard]] double fraction_read() const;
  /// Error at the current line.
  [[nodiscard]] Error error(std::string message) const { return Error{std::move(message), path_, line_number_}; }

 private:
  struct Impl;
  explicit TextReader(std::unique_ptr<Impl> impl, std::string path);
  bool fill();

  std::unique_ptr<Impl> impl_;
  std::string path_;
  std::string buffer_;        // read buffer (zlib source)
  std::string_view view_;     // the text: the mapped file, or buffer_
  std::size_t view_pos_ = 0;  // start of the next line in view_
  std::string_view line_;     // the last line returned (into view_)
  bool pushed_back_ = false;
  bool eof_ = false;
  bool ended_ = false;
  bool line_cut_ = false;
  int line_number_ = 0;
  std::uint64_t file_size_ = 0;  // bytes on disk, 0 if unknown
  std::optional<std::string> read_error_;
};

/// Columns [start, start + width) of `line` (shorter if the line is shorter; empty if it starts past the end).
[[nodiscard]] std::string_view column(std::string_view line, std::size_t start, std::size_t width);
/// `text` without leading and trailing blanks.
[[nodiscard]] std::string_view trim(std::string_view text);

/// A fixed-column number: blank -> `blank_value` (nullopt if none given), Fortran 'D' exponents accepted,
/// anything else that is not a whole number -> nullopt.
[[nodiscard]] std::optional<double> parse_double(std::string_view field, std::optional<double> blank_value = {});
[[nodiscard]] std::optional<int> parse_int(std::string_view field, std::optional<int> blank_value = {});

}  // namespace canyon::io
