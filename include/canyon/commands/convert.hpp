#pragma once
// `canyon convert`: RTCM 3 or u-blox UBX (a file, gzip or not, or a stream on stdin) into RINEX 3.04 observations
// and navigation; RINEX observations (and navigation) into an RTCM 3 stream file.
//
// Binary -> RINEX:
//  - The input may mix RTCM 3, UBX and NMEA (a u-blox port). Observations come from UBX RXM-RAWX when the input has
//    any (or with from = ubx), else from RTCM 3 MSM/1004/1012 (from = rtcm3 forces it). Ephemerides come from both.
//  - RTCM 3 carries times of week only: weeks are resolved against `approx_time` when given, else against the
//    first ephemeris in the stream that dates it (Galileo and BeiDou messages carry 12/13-bit weeks; GPS 10-bit
//    weeks are resolved against the current date), else the current date (with a warning).
//  - The RINEX header takes the marker position from 1005/1006, receiver and antenna from 1033, and the GLONASS
//    channels from the stream.
// RINEX -> RTCM 3: every epoch as MSM (7 by default, 4 on request) with 1005 at the station interval (position from
//  `position` or the header's APPROX POSITION XYZ) and the ephemerides of the --nav files when they become current
//  (see io/rtcm3_station_stream.hpp); the phase of each arc is shifted by an integer number of cycles (RTCM MSM
//  sends phase relative to the pseudorange).

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/result.hpp"
#include "canyon/core/time.hpp"

namespace canyon::commands {

struct ConvertConfig {
  /// Input: a file, "-" (standard input), "tcp://HOST:PORT" or "ntrip://[USER[:PASSWORD]@]HOST:PORT/MOUNT" (a
  /// live stream, recorded until `duration_s` has passed or no byte came for `idle_timeout_s`).
  std::string input;
  std::string from = "auto";  ///< auto | rtcm3 | ubx | rinex | pos (a solution file; implied by kml or gpx)
  // Binary -> RINEX.
  std::string obs_out;                       ///< RINEX observations (default: the input name with .obs)
  std::string nav_out;                       ///< RINEX navigation (default: the input name with .nav)
  std::optional<core::GpsTime> approx_time;  ///< GPST within a few days of the data (RTCM 3 weeks)
  std::string marker;                        ///< RINEX MARKER NAME (default: "RTCM <station id>" or the input name)
  double duration_s = 0.0;                   ///< network input: record this long (0: until idle)
  double idle_timeout_s = 5.0;               ///< network input: stop when no byte came for this long (after the first)
  int ntrip_version = 2;                     ///< network input: NTRIP request version (1 or 2)
  // RINEX -> RTCM 3.
  std::string rtcm_out;                         ///< RTCM 3 output (default: the input name with .rtcm3)
  std::vector<std::string> nav;                 ///< RINEX navigation files whose ephemerides go into the stream
  int station_id = 0;                           ///< DF003, 0-4095
  int msm = 7;                                  ///< 4 or 7 (5 and 6 also accepted)
  double station_interval_s = 10.0;             ///< 1005 every this many seconds (0: once)
  double ephemeris_interval_s = 0.0;            ///< repeat current ephemerides (0: each once, when it becomes current)
  std::optional<Eigen::Vector3d> position_E_m;  ///< 1005 antenna reference point (default: header position)
  // Solutions (.pos) -> map tracks (eval/map_tracks.hpp).
  std::string kml;  ///< KML 2.2 track by status (with --from pos and neither given: the input name with .kml)
  std::string gpx;  ///< GPX 1.1 tracks by status

  /// Empty if valid, else the violated rule.
  [[nodiscard]] std::string validate() const;
};

struct ConvertSummary {
  std::string direction;  ///< "rtcm3 -> rinex", "ubx -> rinex", "rinex -> rtcm3", "pos -> kml, gpx"
  int epochs = 0;
  int ephemerides = 0;
  int messages = 0;                   ///< RTCM 3 frames written (rinex -> rtcm3)
  std::vector<std::string> written;   ///< files written
  std::vector<std::string> warnings;  ///< recovered problems (framing, decode errors with byte offsets, ...)
  std::string statistics;             ///< one line of counts (frames, bad CRCs, garbage bytes, ...)
};

/// Runs the conversion. Error (file, and byte or line) if the input cannot be read or an output cannot be written.
Result<ConvertSummary> run_convert(const ConvertConfig& config);

}  // namespace canyon::commands
