#pragma once
// RINEX observation files, versions 2.10/2.11 and 3.02-3.05 (mixed constellations), plain or gzip-compressed,
// read as a stream of epochs; and a RINEX 3 observation writer.
//
// RINEX 2 observation types are mapped to RINEX 3 signal codes, and RINEX 3.00-3.02 BeiDou band "1" (B1I: C1I,
// L1I, ...) to band "2", so downstream code sees one naming. Times in GLONASS time or BDT files are converted to
// GPST (GLONASS: UTC + 3 h with the header's LEAP SECONDS, else the built-in table; BDT: + 14 s).
//
// RINEX 2 -> RINEX 3 (observation kind letter first; the same band digit for C/L/D/S):
//   GPS:     C1 -> C1C  P1 -> C1W  L1 -> L1C  D1 -> D1C  S1 -> S1C
//            C2 -> C2C  P2 -> C2W  L2 -> L2W  D2 -> D2W  S2 -> S2W
//            C5 -> C5X  L5 -> L5X  D5 -> D5X  S5 -> S5X
//   GLONASS: C1 -> C1C  P1 -> C1P  L1 -> L1C  D1 -> D1C  S1 -> S1C
//            C2 -> C2C  P2 -> C2P  L2 -> L2P  D2 -> D2P  S2 -> S2P
//   Galileo: C1/L1/D1/S1 -> *1X, C5.. -> *5X, C6.. -> *6X, C7.. -> *7X, C8.. -> *8X
// The GPS L1 phase pairs with either C1 or P1 in RINEX 2; it is kept under L1C (and L2 under L2W) whatever code
// the receiver tracked. Other RINEX 2 types (e.g. T1, proprietary) are ignored. A RINEX 2 'M' file declares its
// types for GPS, GLONASS and Galileo; SBAS records are skipped with a warning.
//
// Observation values of 0.0 or blank are missing (NaN). The LLI of the carrier phase is kept; the signal strength
// indicator digits are not read (the S observable gives the SNR). Each SatelliteObs holds only the signals that
// have at least one observable. "SYS / SCALE FACTOR" divisors are applied on reading.

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/io/text_reader.hpp"

namespace canyon::io {

struct RinexObsHeader {
  double version = 0.0;
  char file_system = 'M';  ///< 'G', 'R', 'E', 'C', 'J' or 'M' (mixed)
  core::ReceiverInfo receiver;
  /// Observation codes per system in file order, as RINEX 3 three-character codes ("C1C", "L2W", ...).
  std::map<core::Constellation, std::vector<std::string>> obs_types;
  std::optional<core::GpsTime> first_obs;
  double interval_s = 0.0;          ///< 0 if not given
  std::optional<int> leap_seconds;  ///< GPST - UTC if given
  std::string time_system = "GPS";  ///< of the epoch time tags in the file: GPS, GLO, GAL, BDT, QZS
  /// Writer only: the date field of "PGM / RUN BY / DATE" ("yyyymmdd hhmmss zone", at most 20 characters). Empty:
  /// the current UTC time. A fixed value makes the written file depend on its content only (simulations).
  std::string program_date;
};

class RinexObsReader {
 public:
  /// Opens the file and reads the header. Error (file and line) on unreadable, unsupported or malformed header.
  static Result<RinexObsReader> open(const std::string& path);

  [[nodiscard]] const RinexObsHeader& header() const { return header_; }

  /// Next observation epoch (flags 0, 1, 6; header records of flags 2-5 are read and skipped), nullopt at the end.
  /// Error (file and line) on a malformed epoch that cannot be recovered. Recoverable defects (an epoch that
  /// announces more satellites than it holds, an unknown satellite system) are skipped with a warning.
  Result<std::optional<core::ObsEpoch>> next();

  /// Warnings about recovered defects so far, "file:line: what" each.
  [[nodiscard]] const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  explicit RinexObsReader(TextReader reader) : reader_(std::move(reader)) {}
  Status read_header();
  Status read_version_line();
  /// One header record; `in_epoch` for the header records that an event epoch (flags 2-5) carries.
  Status parse_header_record(std::string_view line, std::string_view label, bool in_epoch);
  Status parse_obs_types_v3(std::string_view line);
  Status parse_obs_types_v2(std::string_view line);
  Status parse_time_of_first_obs(std::string_view line);
  Status parse_glonass_slots(std::string_view line);
  void parse_phase_shift(std::string_view line);
  Status parse_scale_factor(std::string_view line);
  Status finish_header();
  void build_mapping();
  /// Reads the `count` header records following an event epoch line (flags 2-5).
  Status skip_event_records(int count);
  /// Satellite list of a RINEX 2 epoch (continuation lines included) into sat_tokens_.
  Status read_sat_list_v2(std::string_view epoch_line, int count);
  Status read_satellites_v3(core::ObsEpoch& epoch, int count, int epoch_line);
  Status read_satellites_v2(core::ObsEpoch& epoch);
  /// Satellite of a record: its id, nullopt for a record to skip (warned), or an Error.
  Result<std::optional<core::SatelliteId>> resolve_satellite(std::string_view token);
  /// Parses `count` observation fields of 16 columns from column `first_col` of `line` into scratch_.
  Status parse_fields(std::string_view line, std::size_t first_col, std::size_t first_field, std::size_t count,
                      core::Constellation system);
  /// Moves the signals with an observable from scratch_ into a new SatelliteObs of `epoch`.
  void emit_satellite(core::SatelliteId sat, core::ObsEpoch& epoch);
  [[nodiscard]] core::GpsTime to_gps(const core::CalendarTime& c) const;
  void warn(int line, const std::string& message);
  /// Error at end of input: the read error (truncated gzip) if there is one, else `message`.
  [[nodiscard]] Error end_of_input_error(const std::string& message) const;

  TextReader reader_;
  RinexObsHeader header_;
  std::vector<std::string> warnings_;
  // Implementation state (e.g. RINEX 2 per-file type mapping) may be added here.
  struct Mapping;
  std::shared_ptr<const Mapping> mapping_;

  int version_code_ = 0;                                  // version * 100: 210, 211, 300..305
  std::vector<std::string> v2_types_;                     // RINEX 2 "# / TYPES OF OBSERV" as written
  char continued_types_system_ = 0;                       // system whose type list continues on the next header line
  std::size_t expected_types_ = 0;                        // types announced for continued_types_system_
  int obs_types_line_ = 0;                                // line of the last obs types record, for errors
  std::optional<core::CalendarTime> first_obs_calendar_;  // TIME OF FIRST OBS in the file's time system
  core::LeapSecondTable leaps_;                           // for GLONASS time tags
  std::vector<std::string> sat_tokens_;                   // RINEX 2 satellite list of the current epoch
  std::vector<core::SignalObs> scratch_;                  // per-signal accumulator of one satellite record
  std::string warned_systems_;                            // system letters already warned about
  std::vector<std::string> warned_satellites_;
  struct ScaleFactor {
    char system = 0;
    std::string code;  // empty: all types of the system
    double factor = 1.0;
  };
  std::vector<ScaleFactor> scale_factors_;  // "SYS / SCALE FACTOR"
  ScaleFactor continued_scale_;             // system and factor a continuation line refers to
};

/// A whole file in memory.
struct RinexObsFile {
  RinexObsHeader header;
  std::vector<core::ObsEpoch> epochs;
  std::vector<std::string> warnings;
};
Result<RinexObsFile> read_rinex_obs(const std::string& path);

/// Writes RINEX 3.04 observations. Observation types per system are taken from `header.obs_types` if given,
/// else collected from the epochs. Error if the file cannot be written.
Status write_rinex_obs(const std::string& path, const RinexObsHeader& header,
                       const std::vector<core::ObsEpoch>& epochs);

}  // namespace canyon::io
