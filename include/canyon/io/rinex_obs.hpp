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
#include "canyon/core/satellite.hpp"
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

/// Which observations a reader keeps: constellations, and signals up to a frequency rank (core::frequency_rank; 0:
/// L1/E1/B1I/G1 only ... 2: all three). Records and fields left out are skipped without being parsed, so a
/// defect in them is not noticed either; a program that uses only some signals reads faster.
struct ObsFilter {
  core::ConstellationFlags systems;  ///< constellations kept
  int max_frequency_rank = 2;        ///< signals of a higher frequency rank (or of no known rank) are skipped
};

/// The filter applied to an epoch from another source (a receiver's stream): the same satellites and signals a
/// reader with `filter` keeps of the same observations; satellites left with no signal are removed.
void apply_obs_filter(const ObsFilter& filter, core::ObsEpoch& epoch);

class RinexObsReader {
 public:
  /// Opens the file and reads the header. Error (file and line) on unreadable, unsupported or malformed header.
  /// Every observation is kept unless `filter` says otherwise.
  static Result<RinexObsReader> open(const std::string& path, std::optional<ObsFilter> filter = std::nullopt);

  [[nodiscard]] const RinexObsHeader& header() const { return header_; }

  /// Next observation epoch (flags 0, 1, 6; header records of flags 2-5 are read and skipped), nullopt at the end.
  ///
  /// Once the header has been read, a defect in the body costs at most the epoch it is in: it becomes a warning
  /// "file:line: what, ..." (see warnings()) and reading goes on.
  /// - A corrupt epoch (garbled epoch line, unparseable or cut-short observation value, bad satellite id, RINEX 2
  ///   satellite list shorter than its count, lines where an epoch line should be) is skipped: "file:line: what,
  ///   epoch skipped (lines a-b)", or "N epochs skipped" when the lines skipped hold further garbled RINEX 3 epoch
  ///   lines. Reading resumes at the next line that parses as an epoch line (RINEX 3: a line starting with '>'
  ///   whose fields parse; RINEX 2: a line whose epoch fields parse with a valid date from 1980, flag 0-6 and
  ///   satellite count 0-999, and whose satellite list slots hold satellite ids). The line where the defect
  ///   showed is itself examined, so an epoch announcing more records than it holds does not swallow the next one.
  /// - A RINEX 3 epoch with fewer satellite records than announced is kept with what it has (the next '>' line
  ///   ends it); one with more keeps the announced ones and the lines after are skipped as above. A RINEX 2 epoch
  ///   with fewer records than listed satellites is skipped (the list does not say which one has no record).
  /// - End of input inside an epoch (a truncated file, a truncated gzip stream): that last partial epoch is skipped
  ///   with a warning that says so, with the read error if there is one; every epoch before is returned. An epoch
  ///   whose last line is the unterminated tail that a read error left is skipped too.
  /// - An epoch (flag 0 or 1) whose time is not after the previous epoch's (duplicate, or time going backwards) is
  ///   skipped: later stages assume increasing time. A flag 6 epoch (cycle slip records) may repeat the time. A
  ///   corrupt time that still parses as a valid later one cannot be told from a true one: the epochs up to it are
  ///   then skipped as out of order, each with its warning.
  /// - Records of systems canyon does not process, of satellite numbers out of range, or of a system without
  ///   observation types in the header are skipped, one warning per system or satellite.
  /// Error (file and line) only when the body as a whole is not usable observation data, or the data after a point
  /// cannot be interpreted:
  /// - no line of the first kMaxLinesBeforeFirstEpoch after the header parses as an epoch line (garbage, or not
  ///   this RINEX version's layout): as soon as that is clear;
  /// - at the end of the input, more corrupt epochs than valid ones, a body of corrupt epochs only included (after
  ///   the valid epochs have been returned: read_rinex_obs() then returns the Error);
  /// - a header record of an event epoch (flag 4) that cannot be parsed, as in the file header.
  /// Reading always advances: each call consumes at least one line, or reports the end.
  Result<std::optional<core::ObsEpoch>> next();

  /// A body that holds no line parsing as an epoch line within this many lines after the header is an Error: more
  /// than the longest real epoch (RINEX 2: up to 4 lines per satellite, 100+ satellites), so one corrupt first
  /// epoch is still skipped and read past.
  static constexpr int kMaxLinesBeforeFirstEpoch = 1000;

  /// Fraction of the file read so far (0..1), for progress reports.
  [[nodiscard]] double fraction_read() const { return reader_.fraction_read(); }

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
  /// Whether `line` can start an epoch: the resynchronisation test (see next()).
  [[nodiscard]] bool is_epoch_line(std::string_view line) const;
  /// The satellite records of an epoch whose epoch line `line` (at `epoch_line`) parsed into `count` satellites.
  Status read_records(core::ObsEpoch& epoch, std::string_view line, int count, int epoch_line);
  /// Satellite list of a RINEX 2 epoch (continuation lines included) into sat_tokens_.
  Status read_sat_list_v2(std::string_view epoch_line, int count);
  Status read_satellites_v3(core::ObsEpoch& epoch, int count, int epoch_line);
  Status read_satellites_v2(core::ObsEpoch& epoch);
  /// Skips the corrupt epoch that starts at `first_line`, `problem` saying what is wrong: reads up to the next epoch
  /// line (left unread) and warns. Error if the body shows no epoch line in its first kMaxLinesBeforeFirstEpoch.
  Status skip_corrupt_epoch(const Error& problem, int first_line);
  /// Reads up to the next line that is_epoch_line() and leaves it unread (or to the end of the input). The number
  /// of garbled epoch lines (RINEX 3: starting with '>') read past, or an Error as skip_corrupt_epoch() says.
  Result<int> resynchronise();
  /// Whether `epoch` (of `epoch_line`) comes after the previous one; warns about it if not.
  bool in_time_order(const core::ObsEpoch& epoch, const core::CalendarTime& time, int epoch_line);
  /// End of the input: nullopt, with a warning about a read error not reported yet; Error if more epochs were
  /// corrupt than valid.
  Result<std::optional<core::ObsEpoch>> end_of_body();
  /// Satellite of a record: its id, nullopt for a record to skip (warned), or an Error.
  Result<std::optional<core::SatelliteId>> resolve_satellite(std::string_view token);
  /// Parses `count` observation fields of 16 columns from column `first_col` of `line` into scratch_.
  Status parse_fields(std::string_view line, std::size_t first_col, std::size_t first_field, std::size_t count,
                      core::Constellation system);
  /// Moves the signals with an observable from scratch_ into a new SatelliteObs of `epoch`.
  void emit_satellite(core::SatelliteId sat, core::ObsEpoch& epoch);
  [[nodiscard]] core::GpsTime to_gps(const core::CalendarTime& c) const;
  void warn(int line, const std::string& message);
  /// Error at end of input: `message`, with the read error (truncated gzip) if there is one.
  [[nodiscard]] Error end_of_input_error(const std::string& message);

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
  std::optional<ObsFilter> filter_;         // observations kept (all when empty)
  ScaleFactor continued_scale_;             // system and factor a continuation line refers to
  // Body state for recovery.
  int header_end_line_ = 0;                 // line of END OF HEADER
  bool epoch_line_seen_ = false;            // a line of the body has parsed as an epoch line
  int valid_epochs_ = 0;                    // epochs returned
  int corrupt_epochs_ = 0;                  // epochs skipped as corrupt (not those out of time order)
  Error first_corruption_;                  // warning of the first corrupt epoch, for the end-of-body Error
  std::optional<core::GpsTime> last_time_;  // of the last flag 0 or 1 epoch returned
  int last_time_line_ = 0;                  // its epoch line
  bool read_error_reported_ = false;        // the read error is in a warning already
};

/// A whole file in memory.
struct RinexObsFile {
  RinexObsHeader header;
  std::vector<core::ObsEpoch> epochs;
  std::vector<std::string> warnings;
};
/// Every epoch of the file and the reader's warnings; an Error when open() or next() gives one. With a filter, only
/// the observations it keeps (see ObsFilter).
Result<RinexObsFile> read_rinex_obs(const std::string& path, std::optional<ObsFilter> filter = std::nullopt);

/// Writes RINEX 3.04 observations. Observation types per system are taken from `header.obs_types` if given,
/// else collected from the epochs. Error if the file cannot be written.
Status write_rinex_obs(const std::string& path, const RinexObsHeader& header,
                       const std::vector<core::ObsEpoch>& epochs);

}  // namespace canyon::io
