#pragma once
// RINEX observation files, versions 2.10/2.11 and 3.02-3.05 (mixed constellations), plain or gzip-compressed,
// read as a stream of epochs; and a RINEX 3 observation writer.
//
// RINEX 2 observation types are mapped to RINEX 3 signal codes (e.g. C1 -> C1C, P2 -> C2W, L2 -> L2W), and RINEX
// 3.02 BeiDou band "1" (B1I) to band "2", so downstream code sees one naming. Times in GLONASS time or BDT files
// are converted to GPST.

#include <map>
#include <memory>
#include <optional>
#include <string>
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

  TextReader reader_;
  RinexObsHeader header_;
  std::vector<std::string> warnings_;
  // Implementation state (e.g. RINEX 2 per-file type mapping) may be added here.
  struct Mapping;
  std::shared_ptr<const Mapping> mapping_;
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
