#pragma once
// Solutions in RTKLIB's .pos text format, so that RTKLIB's tools (rtkplot, pos2kml) and evaluation scripts read
// canyon's output, and canyon's evaluator reads RTKLIB's.
//
// Header lines start with '%'. Records: time (GPST "week tow" or "yyyy/mm/dd hh:mm:ss.sss"), then either
// latitude/longitude (deg) and ellipsoidal height (m) with ENU standard deviations (sdn sde sdu sdne sdeu sdun; the
// cross terms as sign(c) sqrt(|c|)), or ECEF x y z with sdx sdy sdz sdxy sdyz sdzx; then Q, ns, age (s), ratio.

#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/io/text_file_writer.hpp"

namespace canyon::io {

enum class PosCoordinates { Llh, Ecef };
enum class PosTimeFormat { WeekTow, Calendar };

struct PosWriterOptions {
  PosCoordinates coordinates = PosCoordinates::Llh;
  PosTimeFormat time_format = PosTimeFormat::WeekTow;
  std::vector<std::string> header_lines;  ///< extra "% key : value" lines (program, input files, options)
};

class PosWriter {
 public:
  /// Creates (truncates) `path` and writes the header. Error if it cannot be written.
  static Result<PosWriter> create(const std::string& path, PosWriterOptions options);
  PosWriter(PosWriter&&) noexcept = default;
  PosWriter& operator=(PosWriter&&) noexcept = default;
  ~PosWriter() = default;

  Status write(const core::Solution& solution);
  /// Flushes and closes; reports a write error (e.g. disk full) that happened on the way.
  Status close() { return file_.close(); }

 private:
  PosWriter(TextFileWriter file, PosWriterOptions options) : file_(std::move(file)), options_(std::move(options)) {}

  TextFileWriter file_;
  PosWriterOptions options_;
};

/// One record line in either coordinate form.
[[nodiscard]] std::string format_pos_record(const core::Solution& solution, PosCoordinates coordinates,
                                            PosTimeFormat time_format);

/// Reads a .pos file written by canyon or RTKLIB (either coordinate form and time format, detected per line).
/// Covariance is restored from the standard deviations. Error (file, line) on a malformed record.
Result<std::vector<core::Solution>> read_pos_file(const std::string& path);

}  // namespace canyon::io
