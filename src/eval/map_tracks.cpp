// KML 2.2 and GPX 1.1 tracks of solutions (see map_tracks.hpp).

#include "canyon/eval/map_tracks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>

#include "canyon/core/geodesy.hpp"
#include "canyon/eval/svg.hpp"
#include "canyon/io/text_file_writer.hpp"

namespace canyon::eval {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

struct LatLonHeight {
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double height_m = 0.0;
};

LatLonHeight lat_lon_height(const Eigen::Vector3d& p_E_m) {
  const core::Geodetic g = core::ecef_to_geodetic(p_E_m);
  return {g.lat_rad * kDegPerRad, g.lon_rad * kDegPerRad, g.height_m};
}

/// "2023-06-14T15:59:42.200Z": the UTC instant of GPST `t`, to the millisecond (rounded on the GPST scale first, so
/// that no second reads 60).
std::string utc_text(const core::GpsTime& t, const core::LeapSecondTable& leaps) {
  const auto ms = static_cast<std::int64_t>(
      std::llround((t.week * double(core::kSecondsPerWeek) + t.tow_s - leaps.gps_minus_utc_at_gps(t)) * 1000.0));
  const std::int64_t whole_s = ms / 1000;
  const core::GpsTime whole{static_cast<int>(whole_s / core::kSecondsPerWeek),
                            static_cast<double>(whole_s % core::kSecondsPerWeek)};
  const core::CalendarTime c = core::gps_to_calendar(whole);
  char text[40];
  std::snprintf(text, sizeof text, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", c.year, c.month, c.day, c.hour, c.minute,
                static_cast<int>(std::lround(c.second)), static_cast<int>(ms % 1000));
  return text;
}

/// The KML style id of a status and its colour (aabbggrr).
struct KmlStyle {
  const char* id;
  const char* colour;
};
KmlStyle kml_style(core::SolutionStatus status) {
  switch (status) {
    case core::SolutionStatus::Fixed: return {"fixed", "ff00ff00"};
    case core::SolutionStatus::Float: return {"float", "ff00ffff"};
    case core::SolutionStatus::Single: return {"single", "ff0000ff"};
    case core::SolutionStatus::VioFillIn: return {"fill-in", "ffff0000"};
    default: return {"other", "ff808080"};
  }
}

constexpr core::SolutionStatus kStatuses[] = {core::SolutionStatus::Fixed, core::SolutionStatus::Float,
                                              core::SolutionStatus::Single, core::SolutionStatus::VioFillIn,
                                              core::SolutionStatus::None};

std::string coordinates_text(const LatLonHeight& g) {
  char text[80];
  std::snprintf(text, sizeof text, "%.9f,%.9f,%.4f", g.lon_deg, g.lat_deg, g.height_m);
  return text;
}

void append_kml_styles(std::string& out) {
  for (const core::SolutionStatus s : kStatuses) {
    const KmlStyle style = kml_style(s);
    out += std::string("<Style id=\"") + style.id + "\"><IconStyle><color>" + style.colour +
           "</color><scale>0.4</scale><Icon><href>http://maps.google.com/mapfiles/kml/shapes/placemark_circle.png"
           "</href></Icon></IconStyle><LabelStyle><scale>0</scale></LabelStyle></Style>\n";
  }
  out += "<Style id=\"track\"><LineStyle><color>ffc0c0c0</color><width>1</width></LineStyle></Style>\n";
  out += "<Style id=\"truth\"><LineStyle><color>ffffffff</color><width>2</width></LineStyle></Style>\n";
}

void append_kml_line(std::string& out, const std::string& name, const char* style,
                     const std::vector<std::string>& coordinates) {
  out += "<Placemark><name>" + xml_escape(name) + "</name><styleUrl>#" + style +
         "</styleUrl><LineString><tessellate>1</tessellate><coordinates>";
  for (std::size_t k = 0; k < coordinates.size(); ++k) out += (k == 0 ? "" : " ") + coordinates[k];
  out += "</coordinates></LineString></Placemark>\n";
}

void append_kml_track(std::string& out, const MapTrack& track, const core::LeapSecondTable& leaps) {
  out += "<Folder><name>" + xml_escape(track.name) + "</name>\n";
  std::vector<std::string> line;
  for (const core::Solution& s : track.solutions) {
    if (s.status == core::SolutionStatus::None) continue;
    const std::string at = coordinates_text(lat_lon_height(s.p_E_m));
    line.push_back(at);
    out += "<Placemark><description>" + map_status_name(s.status) + ", " + std::to_string(s.num_satellites) +
           " satellites</description><TimeStamp><when>" + utc_text(s.time, leaps) + "</when></TimeStamp><styleUrl>#" +
           kml_style(s.status).id + "</styleUrl><Point><coordinates>" + at + "</coordinates></Point></Placemark>\n";
  }
  if (line.size() >= 2) append_kml_line(out, track.name + " track", "track", line);
  out += "</Folder>\n";
}

const char* gpx_fix(core::SolutionStatus status) {
  switch (status) {
    case core::SolutionStatus::Fixed:
    case core::SolutionStatus::Float: return "dgps";
    case core::SolutionStatus::Single: return "3d";
    default: return "none";
  }
}

std::string gpx_point(const Eigen::Vector3d& p_E_m, const core::GpsTime& t, const core::LeapSecondTable& leaps,
                      const core::Solution* solution) {
  const LatLonHeight g = lat_lon_height(p_E_m);
  char head[120];
  std::snprintf(head, sizeof head, "<trkpt lat=\"%.9f\" lon=\"%.9f\"><ele>%.4f</ele>", g.lat_deg, g.lon_deg,
                g.height_m);
  std::string out = head;
  out += "<time>" + utc_text(t, leaps) + "</time>";
  if (solution != nullptr) {
    out += "<type>" + map_status_name(solution->status) + "</type><fix>" + gpx_fix(solution->status) + "</fix><sat>" +
           std::to_string(std::max(solution->num_satellites, 0)) + "</sat>";
  }
  return out + "</trkpt>\n";
}

/// One <trk> of the epochs of `track` with `status` (None: every status without a style of its own), a <trkseg> per
/// run of consecutive such epochs.
void append_gpx_status_track(std::string& out, const MapTrack& track, core::SolutionStatus status,
                             const core::LeapSecondTable& leaps) {
  std::string body;
  bool open = false;
  for (const core::Solution& s : track.solutions) {
    if (s.status == core::SolutionStatus::None) continue;
    const bool mine =
        (status == core::SolutionStatus::None) ? kml_style(s.status).id == kml_style(status).id : s.status == status;
    if (mine && !open) body += "<trkseg>\n";
    if (!mine && open) body += "</trkseg>\n";
    open = mine;
    if (mine) body += gpx_point(s.p_E_m, s.time, leaps, &s);
  }
  if (open) body += "</trkseg>\n";
  if (body.empty()) return;
  const std::string name = map_status_name(status);
  out +=
      "<trk><name>" + xml_escape(track.name) + ": " + name + "</name><type>" + name + "</type>\n" + body + "</trk>\n";
}

}  // namespace

std::string map_status_name(core::SolutionStatus status) {
  switch (status) {
    case core::SolutionStatus::Fixed: return "fixed";
    case core::SolutionStatus::Float: return "float";
    case core::SolutionStatus::Single: return "single";
    case core::SolutionStatus::VioFillIn: return "fill-in";
    default: return "other";
  }
}

std::string format_kml(const MapTracks& tracks, const core::LeapSecondTable& leaps) {
  std::string out =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n<Document>\n"
      "<name>canyon solutions</name>\n";
  append_kml_styles(out);
  for (const MapTrack& track : tracks.tracks) append_kml_track(out, track, leaps);
  if (!tracks.truth.empty()) {
    std::vector<std::string> line;
    line.reserve(tracks.truth.size());
    for (const TruthSample& t : tracks.truth) line.push_back(coordinates_text(lat_lon_height(t.p_E_m)));
    out += "<Folder><name>truth</name>\n";
    if (line.size() == 1) {
      out +=
          "<Placemark><name>truth</name><Point><coordinates>" + line.front() + "</coordinates></Point></Placemark>\n";
    } else {
      append_kml_line(out, "truth", "truth", line);
    }
    out += "</Folder>\n";
  }
  return out + "</Document>\n</kml>\n";
}

std::string format_gpx(const MapTracks& tracks, const core::LeapSecondTable& leaps) {
  std::string out =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<gpx version=\"1.1\" creator=\"canyon\" "
      "xmlns=\"http://www.topografix.com/GPX/1/1\" xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
      "xsi:schemaLocation=\"http://www.topografix.com/GPX/1/1 http://www.topografix.com/GPX/1/1/gpx.xsd\">\n"
      "<metadata><name>canyon solutions</name></metadata>\n";
  for (const MapTrack& track : tracks.tracks) {
    for (const core::SolutionStatus s : kStatuses) append_gpx_status_track(out, track, s, leaps);
  }
  if (!tracks.truth.empty()) {
    out += "<trk><name>truth</name><type>truth</type>\n<trkseg>\n";
    for (const TruthSample& t : tracks.truth) out += gpx_point(t.p_E_m, t.time, leaps, nullptr);
    out += "</trkseg>\n</trk>\n";
  }
  return out + "</gpx>\n";
}

Status write_kml(const std::string& path, const MapTracks& tracks) {
  return io::write_text_file(path, format_kml(tracks, core::builtin_leap_seconds()), "KML file");
}

Status write_gpx(const std::string& path, const MapTracks& tracks) {
  return io::write_text_file(path, format_gpx(tracks, core::builtin_leap_seconds()), "GPX file");
}

}  // namespace canyon::eval
