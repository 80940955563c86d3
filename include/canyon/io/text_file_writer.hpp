#pragma once
// A text output file written line by line (.pos, .nmea, ...): creates its folder, reports write errors (disk full)
// with the path, and closes on destruction. The one place canyon's text writers get their file handling from.

#include <cstdio>
#include <memory>
#include <string>
#include <string_view>

#include "canyon/core/result.hpp"

namespace canyon::io {

class TextFileWriter {
 public:
  /// Creates (truncates) `path`, creating its folder if needed. `what` names the file kind in errors
  /// ("solution file", "NMEA file").
  static Result<TextFileWriter> create(const std::string& path, std::string what);

  /// Writes `line` followed by `end_of_line`.
  Status write_line(std::string_view line, std::string_view end_of_line = "\n");
  /// Flushes and closes; reports a write error that happened on the way. Further writes are errors.
  Status close();
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  struct FileCloser {
    void operator()(std::FILE* f) const {
      if (f != nullptr) std::fclose(f);
    }
  };
  TextFileWriter(std::unique_ptr<std::FILE, FileCloser> file, std::string path, std::string what)
      : file_(std::move(file)), path_(std::move(path)), what_(std::move(what)) {}

  std::unique_ptr<std::FILE, FileCloser> file_;
  std::string path_;
  std::string what_;
};

/// Writes `text` as the whole of `path` (created or truncated, its folder created); errors name the path and `what`.
Status write_text_file(const std::string& path, const std::string& text, std::string what);

}  // namespace canyon::io
