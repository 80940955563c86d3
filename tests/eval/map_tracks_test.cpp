// The KML and GPX track writers: UTC times (leap seconds, milliseconds that do not round into a 60th second), every
// solved epoch once with its status, Q 0 skipped, labels escaped, the truth beside the tracks, write errors named.
// tests/eval/map_tracks_check.py reads whole files back with independent readers.

#include "canyon/eval/map_tracks.hpp"

#include <string>

#include <gtest/gtest.h>

#include "canyon/core/geodesy.hpp"

namespace canyon::eval {
namespace {

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

core::Solution solution(double tow_s, core::SolutionStatus status) {
  core::Solution s;
  s.time = core::GpsTime{2266, tow_s};
  s.status = status;
  s.p_E_m = core::geodetic_to_ecef({0.83, -2.135, 20.0});
  s.num_satellites = 12;
  return s;
}

MapTracks walk() {
  MapTracks tracks;
  MapTrack track{"fusion <a&b>", {}};
  track.solutions = {
      solution(316800.0, core::SolutionStatus::Fixed),     solution(316800.2, core::SolutionStatus::Fixed),
      solution(316800.4, core::SolutionStatus::Float),     solution(316800.6, core::SolutionStatus::None),
      solution(316800.8, core::SolutionStatus::VioFillIn), solution(316801.0, core::SolutionStatus::Single),
      solution(316801.2, core::SolutionStatus::Fixed)};
  tracks.tracks.push_back(track);
  tracks.truth = {{core::GpsTime{2266, 316800.0}, track.solutions[0].p_E_m},
                  {core::GpsTime{2266, 316801.2}, track.solutions[6].p_E_m}};
  return tracks;
}

TEST(MapTracks, KmlHasEveryEpochWithItsStatusAndUtcTime) {
  const std::string kml = format_kml(walk(), core::builtin_leap_seconds());
  EXPECT_EQ(count(kml, "<Point>"), 6u);  // Q 0 skipped
  EXPECT_EQ(count(kml, "<styleUrl>#fixed</styleUrl>"), 3u);
  EXPECT_EQ(count(kml, "<styleUrl>#float</styleUrl>"), 1u);
  EXPECT_EQ(count(kml, "<styleUrl>#fill-in</styleUrl>"), 1u);
  EXPECT_EQ(count(kml, "<styleUrl>#single</styleUrl>"), 1u);
  // GPST 2266 316800 is Wednesday 2023-06-14 16:00:00 GPST, 18 s ahead of UTC.
  EXPECT_NE(kml.find("<when>2023-06-14T15:59:42.000Z</when>"), std::string::npos);
  EXPECT_NE(kml.find("<when>2023-06-14T15:59:43.200Z</when>"), std::string::npos);
  EXPECT_NE(kml.find("<name>fusion &lt;a&amp;b&gt;</name>"), std::string::npos);
  EXPECT_EQ(count(kml, "<LineString>"), 2u);  // the track's line and the truth
  EXPECT_NE(kml.find("<Folder><name>truth</name>"), std::string::npos);
}

TEST(MapTracks, GpxHasATrackPerStatusAndEveryEpochOnce) {
  const std::string gpx = format_gpx(walk(), core::builtin_leap_seconds());
  EXPECT_EQ(count(gpx, "<trkpt "), 6u + 2u);  // six epochs and two truth samples
  EXPECT_EQ(count(gpx, "<type>fixed</type><fix>dgps</fix>"), 3u);
  EXPECT_EQ(count(gpx, "<type>single</type><fix>3d</fix>"), 1u);
  EXPECT_EQ(count(gpx, "<type>fill-in</type><fix>none</fix>"), 1u);
  // The fixes run 0-0.2 s and again at 1.2 s: one track, two segments.
  EXPECT_NE(gpx.find("<trk><name>fusion &lt;a&amp;b&gt;: fixed</name><type>fixed</type>"), std::string::npos);
  const std::size_t fixed_at = gpx.find(": fixed</name>");
  const std::size_t next_track = gpx.find("<trk>", fixed_at);
  EXPECT_EQ(count(gpx.substr(fixed_at, next_track - fixed_at), "<trkseg>"), 2u);
  EXPECT_NE(gpx.find("<trk><name>truth</name>"), std::string::npos);
}

TEST(MapTracks, MillisecondsNeverRoundIntoASixtiethSecond) {
  MapTracks tracks;
  tracks.tracks.push_back({"t", {solution(316817.9999996, core::SolutionStatus::Fixed)}});
  const std::string kml = format_kml(tracks, core::builtin_leap_seconds());
  EXPECT_NE(kml.find("<when>2023-06-14T16:00:00.000Z</when>"), std::string::npos) << kml;
}

TEST(MapTracks, AnUnwritablePathIsAnErrorNamingIt) {
  const Status s = write_kml("/dev/null/tracks.kml", walk());
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().to_string().find("/dev/null/tracks.kml"), std::string::npos) << s.error().to_string();
  EXPECT_FALSE(write_gpx("/dev/null/tracks.gpx", walk()));
}

}  // namespace
}  // namespace canyon::eval
