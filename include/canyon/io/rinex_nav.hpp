#pragma once
// RINEX navigation files: 2.x GPS (.n) and GLONASS (.g), 3.x mixed (GPS, GLONASS, Galileo, BeiDou, QZSS; SBAS and
// IRNSS records are skipped), plain or gzip-compressed; and a RINEX 3.04 navigation writer.
// All times are converted to GPST on reading (see canyon/core/ephemeris.hpp).

#include <string>
#include <vector>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/time.hpp"

namespace canyon::io {

struct RinexNavFile {
  core::NavigationData nav;
  std::vector<std::string> warnings;  ///< skipped records, "file:line: what"
};

/// Reads a navigation file. `leaps` converts GLONASS UTC times (the header's LEAP SECONDS, if present, overrides the
/// table's value for the file's time span). Error (file and line) on malformed content that cannot be recovered.
Result<RinexNavFile> read_rinex_nav(const std::string& path,
                                    const core::LeapSecondTable& leaps = core::builtin_leap_seconds());

/// Writes RINEX 3.04 mixed navigation (header with ionosphere parameters and leap seconds if known).
Status write_rinex_nav(const std::string& path, const core::NavigationData& nav,
                       const core::LeapSecondTable& leaps = core::builtin_leap_seconds());

}  // namespace canyon::io
