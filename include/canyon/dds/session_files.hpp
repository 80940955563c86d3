#pragma once
// A recorded session's rover inputs as the files `canyon process` reads (canyon play --extract DIR; canyon process
// --session runs it): the rover's observation epochs of canyon/observations (canyon rover with
// dds.publish_observations) as RINEX 3.04 (DIR/rover.obs), the base's RTCM 3 frames of canyon/rtcm as they were sent
// (DIR/base.rtcm3, which canyon process --base reads), the ephemerides in those frames as RINEX 3.04 navigation
// (DIR/nav.rnx), the VIO poses and time-sync pairs of canyon/vio and canyon/timesync as vio.csv and timesync.csv with
// every digit (17 significant). Each message is decoded with its type (the session's CDR payloads); a message that
// does not decode is counted and named in the problems, the rest is used. Messages are taken in recording order; a
// sample recorded twice (the same sequence number) is taken once.

#include <string>
#include <vector>

#include "canyon/core/result.hpp"

namespace canyon::dds {

struct SessionFiles {
  std::string rover_obs;              ///< empty: the session has no canyon/observations
  std::string base_rtcm;              ///< empty: no canyon/rtcm
  std::string nav;                    ///< empty: no ephemeris in the RTCM frames
  std::string vio;                    ///< empty: no canyon/vio
  std::string timesync;               ///< empty: no canyon/timesync
  std::vector<std::string> written;   ///< what was written, a line per input
  std::vector<std::string> problems;  ///< a cut file, messages left out (the first problem of each topic)
};

/// Writes the files into `dir` (created). Error naming the session: not readable as MCAP, or a file that cannot be
/// written; a session cut short gives the files of the messages before the cut (a problem says so).
Result<SessionFiles> extract_session(const std::string& session, const std::string& dir);

}  // namespace canyon::dds
