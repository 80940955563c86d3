#pragma once
// NMEA 0183 GGA output (and a parser for it): for receivers' consumers, logging, and the position an NTRIP client
// uploads to a caster.
//
// Sentence written (fields of NMEA 0183 v4.10 GGA):
//   $GPGGA,hhmmss.ss,ddmm.mmmmmmm,N|S,dddmm.mmmmmmm,E|W,q,nn,hdop,alt,M,sep,M,age,stn*CS
//  - Talker "GP" for every constellation, as RTKLIB does: the sentence NTRIP casters and older consumers accept
//    ("GN" is parsed too).
//  - Time: UTC (GPST minus the leap seconds of the table passed in), rounded to 0.01 s.
//  - Latitude/longitude: degrees and minutes, minutes with 7 decimals (about 0.2 mm), hemisphere letters.
//  - Quality q: canyon status 1 fixed -> 4 (RTK fixed), 2 float -> 5 (RTK float), 5 single -> 1 (GPS fix),
//    7 VIO fill-in -> 6 (dead reckoning), none -> 0 (invalid; position fields then empty).
//  - HDOP: GgaOptions::hdop when given; otherwise empty (canyon's Solution carries no satellite geometry, and a
//    covariance is not a dilution of precision).
//  - Altitude: canyon has no geoid model, so the altitude field carries the ELLIPSOIDAL height and the geoid
//    separation is 0.000 (as RTKLIB writes when no geoid is configured). alt + sep is the ellipsoidal height either
//    way.
//  - Age of corrections (s, 1 decimal) and reference station id (0000-1023, NMEA's range; others leave it empty): only
//  for differential solutions
//    (fixed, float); empty otherwise, or when no station id is given.
//  - Checksum: XOR of every character between '$' and '*', two upper-case hex digits; lines end in CR LF.

#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/core/time.hpp"
#include "canyon/io/text_file_writer.hpp"

namespace canyon::io {

struct GgaOptions {
  std::optional<double> hdop;     ///< horizontal dilution of precision; nullopt: empty field
  std::optional<int> station_id;  ///< reference station id, 0..1023; nullopt or out of range: empty field
};

/// The GGA sentence of `solution` including "$", "*" and the checksum, without the line end.
[[nodiscard]] std::string format_gga(const core::Solution& solution,
                                     const core::LeapSecondTable& leaps = core::builtin_leap_seconds(),
                                     const GgaOptions& options = {});

/// XOR of the characters of `body` (the part between '$' and '*').
[[nodiscard]] std::uint8_t nmea_checksum(std::string_view body);

/// Fix quality of a canyon status (see above).
[[nodiscard]] int gga_quality(core::SolutionStatus status);

/// A parsed GGA sentence.
struct GgaSentence {
  std::string talker;  ///< "GP", "GN", ...
  double utc_seconds_of_day = 0.0;
  int quality = 0;
  std::optional<double> lat_deg;  ///< + north; nullopt when the field is empty
  std::optional<double> lon_deg;  ///< + east
  int num_satellites = 0;
  std::optional<double> hdop;
  std::optional<double> altitude_m;  ///< above the geoid (canyon: above the ellipsoid, see above)
  std::optional<double> geoid_separation_m;
  std::optional<double> age_s;
  std::optional<int> station_id;
};

/// Parses one GGA sentence (with or without the line end). Error naming the field when the checksum is missing or
/// wrong, the sentence is not GGA, or a field is malformed.
Result<GgaSentence> parse_gga(std::string_view sentence);

/// Writes GGA sentences, one per solution, to a .nmea file (CR LF line ends).
class NmeaWriter {
 public:
  /// Creates (truncates) `path`. Error if it cannot be written.
  static Result<NmeaWriter> create(const std::string& path, core::LeapSecondTable leaps = core::builtin_leap_seconds(),
                                   GgaOptions options = {});
  NmeaWriter(NmeaWriter&&) noexcept = default;
  NmeaWriter& operator=(NmeaWriter&&) noexcept = default;
  ~NmeaWriter() = default;

  /// One GGA sentence; `hdop` overrides the writer's GgaOptions::hdop for this solution.
  Status write(const core::Solution& solution, std::optional<double> hdop = std::nullopt);
  /// Flushes and closes; reports a write error (e.g. disk full) that happened on the way.
  Status close() { return file_.close(); }

 private:
  NmeaWriter(TextFileWriter file, core::LeapSecondTable leaps, GgaOptions options)
      : file_(std::move(file)), leaps_(std::move(leaps)), options_(options) {}

  TextFileWriter file_;
  core::LeapSecondTable leaps_;
  GgaOptions options_;
};

}  // namespace canyon::io
