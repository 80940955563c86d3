#pragma once
// Tracks for maps: solutions as KML 2.2 (Google Earth; the paper's figures are Google Earth views) and GPX 1.1
// (map and GIS tools), coloured by solution status as RTKLIB's pos2kml colours them, with the truth beside them.
//
// KML: one Folder per track. A solution track has one Placemark per epoch (a Point, its TimeStamp in UTC, the style
// of its status) and a LineString through all of them; the truth is a white LineString. Points are clamped to the
// ground (heights are ellipsoidal, Google Earth's are above the geoid). Styles (KML colours are aabbggrr):
//   fixed (Q 1) green, float (Q 2) yellow, single (Q 5) red, VIO fill-in (Q 7) blue, other Q grey.
// GPX: one <trk> per track and status ("fusion: fixed"), its <type> the status and one <trkseg> per run of
// consecutive epochs with that status, so that map tools draw each status in its own colour; every epoch is one
// <trkpt> with <ele> (ellipsoidal height), <time> (UTC), <type> (status), <fix> (fixed and float: dgps, single: 3d,
// fill-in: none; the VIO fill-in is no GNSS fix) and <sat>. The truth is one <trk> with its samples.

#include <string>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/core/time.hpp"
#include "canyon/eval/truth.hpp"

namespace canyon::eval {

struct MapTrack {
  std::string name;                       ///< e.g. "fusion" (the evaluation's label)
  std::vector<core::Solution> solutions;  ///< in time order; Q 0 records are skipped
};

struct MapTracks {
  std::vector<MapTrack> tracks;
  std::vector<TruthSample> truth;  ///< drawn beside the tracks when not empty
};

/// The status's name in the files ("fixed", "float", "single", "fill-in", "Q N").
[[nodiscard]] std::string map_status_name(core::SolutionStatus status);

/// KML 2.2 document text (see above); times in UTC by `leaps`.
[[nodiscard]] std::string format_kml(const MapTracks& tracks, const core::LeapSecondTable& leaps);
/// GPX 1.1 document text (see above).
[[nodiscard]] std::string format_gpx(const MapTracks& tracks, const core::LeapSecondTable& leaps);

/// Writes format_kml() / format_gpx() to `path` (its folder created); an Error names the path.
Status write_kml(const std::string& path, const MapTracks& tracks);
Status write_gpx(const std::string& path, const MapTracks& tracks);

}  // namespace canyon::eval
