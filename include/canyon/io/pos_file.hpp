#pragma once
// Solutions in RTKLIB's .pos text format, so that RTKLIB's tools (rtkplot, pos2kml) and evaluation scripts read
// canyon's output, and canyon's evaluator reads RTKLIB's.
//
// Header lines start with '%'. Records: time (GPST "week tow" or "yyyy/mm/dd hh:mm:ss.sss"), then either
// latitude/longitude (deg) and ellipsoidal height (m) with ENU standard deviations (sdn sde sdu sdne sdeu sdun; the
// cross terms as sign(c) sqrt(|c|)), or ECEF x y z with sdx sdy sdz sdxy sdyz sdzx; then Q, ns, age (s), ratio.
// canyon writes these two forms; the reader also takes RTKLIB's other forms (see read_pos_file).

#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/core/time.hpp"
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

/// Reads a .pos file written by canyon or RTKLIB, in every form RTKLIB writes (layout from the header's column
/// titles line, `%  GPST ...`, which RTKLIB writes even with out-outhead=off):
///  - time: GPST week and seconds of week or calendar time (out-timeform tow/hms, any out-timendec), on the GPST,
///    UTC or JST scale (out-timesys; the first word of the column titles). UTC and JST times, including RTKLIB's
///    "week tow" of a UTC or JST instant, are converted to GPST with `leaps`.
///  - position: latitude/longitude in decimal degrees or in degrees, minutes, seconds (out-degform=dms; the sign on
///    the degrees, "-0" included) with ellipsoidal height; ECEF x/y/z; or the e/n/u baseline (out-solformat=enu) from
///    the base position of the `% ref pos` header line (ENU at the base; an Error if that line is missing).
///  - any out-fieldsep: characters of the column titles line that cannot be part of a title separate fields too.
///  - RTKLIB's optional velocity columns (out-outvel) are ignored.
/// Without a column titles line: GPST, blanks as separators, and latitude/longitude/height when the three position
/// values look like it (|lat| <= 90, |lon| <= 360, |h| < 100 km), else ECEF. Heights above the geoid
/// (out-height=geodetic) and NMEA files (out-solformat=nmea) are Errors: they cannot be turned into ECEF positions.
/// Q must be 0-7; standard deviations, age and ratio are optional, but numbers where present. Covariance is
/// restored from the standard deviations. Error (file, line) on a malformed record.
Result<std::vector<core::Solution>> read_pos_file(const std::string& path, const core::LeapSecondTable& leaps);
/// read_pos_file() with the built-in leap seconds (core::builtin_leap_seconds()).
Result<std::vector<core::Solution>> read_pos_file(const std::string& path);

}  // namespace canyon::io
