// Line-by-line text output files (see text_file_writer.hpp).

#include "canyon/io/text_file_writer.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace canyon::io {

Result<TextFileWriter> TextFileWriter::create(const std::string& path, std::string what) {
  // Create the output folder as users expect; a failure shows up as the fopen error below.
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) {
    std::error_code ignored;
    std::filesystem::create_directories(parent, ignored);
  }
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "wb"));
  if (!file) return Error{"cannot create " + what + ": " + std::strerror(errno), path, 0};
  return TextFileWriter(std::move(file), path, std::move(what));
}

Status TextFileWriter::write_line(std::string_view line, std::string_view end_of_line) {
  if (!file_) return Error{"write after close of " + what_, path_, 0};
  if (std::fwrite(line.data(), 1, line.size(), file_.get()) != line.size() ||
      std::fwrite(end_of_line.data(), 1, end_of_line.size(), file_.get()) != end_of_line.size()) {
    return Error{"cannot write " + what_ + ": " + std::strerror(errno), path_, 0};
  }
  return Ok{};
}

Status TextFileWriter::close() {
  if (!file_) return Ok{};
  const bool failed = std::ferror(file_.get()) != 0;
  std::FILE* f = file_.release();
  if (std::fclose(f) != 0 || failed) return Error{"error writing " + what_, path_, 0};
  return Ok{};
}

Status write_text_file(const std::string& path, const std::string& text, std::string what) {
  auto file = TextFileWriter::create(path, std::move(what));
  if (!file) return file.error();
  if (Status s = file->write_line(text, ""); !s) return s;
  return file->close();
}

}  // namespace canyon::io
