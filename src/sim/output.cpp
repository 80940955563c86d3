// Writing a simulation's files (see simulator.hpp): RINEX observations, truth.csv, city.geojson.
//
// truth.csv: header `gps_week,gps_tow_s,x,y,z,qx,qy,qz,qw`, one row per rover epoch: the antenna position (ECEF, m)
// at that GPST instant and the body attitude R_EI as a Hamilton quaternion (I: x along the walking direction, y to
// the left, z up).
// city.geojson: a GeoJSON FeatureCollection in WGS84 longitude/latitude (degrees): buildings (Polygon, properties
// kind "building", height_m above the ground), trees (Point, kind "tree", radius_m, bottom_m, top_m), the route
// (LineString, kind "route", the corner points walked), the base (Point, kind "base", height_m ellipsoidal) and the
// city origin (Point, kind "origin", ground height_m ellipsoidal).
// vio.csv (DESIGN.md): header `t_ns,px,py,pz,qx,qy,qz,qw`, then `cov_R_C` for the 21 entries of the upper triangle
// (row-major) of the 6x6 covariance of xi_OI = [delta p; delta theta], then `xcov_R_C` for the 36 entries
// (row-major) of cov(xi_OI of the previous row, xi_OI of this row) -- zero on the first row. T_OI as the VIO
// reports it, device clock.
// timesync.csv (DESIGN.md): header `t_ns,gps_week,gps_tow_s`: device clock when the built-in GPS gave that time.

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/io/text_file_writer.hpp"
#include "canyon/io/vio_file.hpp"
#include "canyon/sim/simulator.hpp"

namespace canyon::sim {
namespace {

template <typename... Args>
std::string format(const char* fmt, Args... args) {
  char buffer[512];
  const int n = std::snprintf(buffer, sizeof buffer, fmt, args...);
  return std::string(buffer, n < 0 ? 0 : std::min<std::size_t>(static_cast<std::size_t>(n), sizeof buffer - 1));
}

Status write_truth(const Simulation& sim, const std::string& path) {
  auto file = io::TextFileWriter::create(path, "truth file");
  if (!file) return file.error();
  if (Status s = file->write_line("gps_week,gps_tow_s,x,y,z,qx,qy,qz,qw"); !s) return s;
  for (const TruthSample& t : sim.truth) {
    const core::GpsTime n = t.time.normalized();
    const Eigen::Quaterniond& q = t.q_EI;
    const std::string line = format("%d,%.3f,%.4f,%.4f,%.4f,%.9f,%.9f,%.9f,%.9f", n.week, n.tow_s, t.p_E_m.x(),
                                    t.p_E_m.y(), t.p_E_m.z(), q.x(), q.y(), q.z(), q.w());
    if (Status s = file->write_line(line); !s) return s;
  }
  return file->close();
}

/// "[lon,lat]" of a city ENU point at ground level.
std::string lon_lat(const Eigen::Vector2d& p_N, const core::Geodetic& origin) {
  const Eigen::Vector3d p_E =
      core::geodetic_to_ecef(origin) + core::enu_to_ecef(Eigen::Vector3d(p_N.x(), p_N.y(), 0.0), origin);
  const core::Geodetic g = core::ecef_to_geodetic(p_E);
  return format("[%.8f,%.8f]", g.lon_rad * core::kRadToDeg, g.lat_rad * core::kRadToDeg);
}

std::string point_feature(const std::string& coordinates, const std::string& properties) {
  return R"({"type":"Feature","geometry":{"type":"Point","coordinates":)" + coordinates + R"(},"properties":{)" +
         properties + "}}";
}

Status write_city(const Simulation& sim, const std::string& path) {
  auto file = io::TextFileWriter::create(path, "city file");
  if (!file) return file.error();
  const core::Geodetic& origin = sim.scenario.origin;
  std::vector<std::string> features;
  for (const Building& b : sim.city.buildings()) {
    std::string ring;
    for (const Eigen::Vector2d& p : b.footprint_N_m) ring += lon_lat(p, origin) + ",";
    ring += lon_lat(b.footprint_N_m.front(), origin);
    features.push_back(R"({"type":"Feature","geometry":{"type":"Polygon","coordinates":[[)" + ring +
                       R"(]]},"properties":{"kind":"building","height_m":)" + format("%.2f", b.height_m) + "}}");
  }
  for (const Tree& t : sim.city.trees()) {
    features.push_back(point_feature(
        lon_lat(t.center_N_m, origin),
        format(R"("kind":"tree","radius_m":%.2f,"bottom_m":%.2f,"top_m":%.2f)", t.radius_m, t.bottom_m, t.top_m)));
  }
  std::string line;
  for (const Eigen::Vector2d& p : sim.trajectory.path().points_N()) {
    if (!line.empty()) line += ',';
    line += lon_lat(p, origin);
  }
  features.push_back(R"({"type":"Feature","geometry":{"type":"LineString","coordinates":[)" + line +
                     R"(]},"properties":{"kind":"route"}})");
  const core::Geodetic base = core::ecef_to_geodetic(sim.base_p_E_m);
  features.push_back(
      point_feature(format("[%.8f,%.8f]", base.lon_rad * core::kRadToDeg, base.lat_rad * core::kRadToDeg),
                    format(R"("kind":"base","height_m":%.4f)", base.height_m)));
  features.push_back(point_feature(lon_lat(Eigen::Vector2d::Zero(), origin),
                                   format(R"("kind":"origin","height_m":%.4f)", origin.height_m)));
  if (Status s = file->write_line(R"({"type":"FeatureCollection","features":[)"); !s) return s;
  for (std::size_t i = 0; i < features.size(); ++i) {
    if (Status s = file->write_line(features[i] + (i + 1 < features.size() ? "," : "")); !s) return s;
  }
  if (Status s = file->write_line("]}"); !s) return s;
  return file->close();
}

Status write_vio(const VioRun& vio, const std::string& path) {
  auto file = io::TextFileWriter::create(path, "VIO file");
  if (!file) return file.error();
  if (Status s = file->write_line(io::vio_csv_header()); !s) return s;
  std::string line;
  for (const VioSample& v : vio.poses) {
    const Eigen::Quaterniond q = v.T_OI.q.normalized();
    line = format("%lld,%.6f,%.6f,%.6f,%.12f,%.12f,%.12f,%.12f", static_cast<long long>(v.t_ns), v.T_OI.p.x(),
                  v.T_OI.p.y(), v.T_OI.p.z(), q.x(), q.y(), q.z(), q.w());
    for (int r = 0; r < 6; ++r) {
      for (int c = r; c < 6; ++c) line += format(",%.10e", v.covariance(r, c));
    }
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) line += format(",%.10e", v.cross_previous(r, c));
    }
    if (Status s = file->write_line(line); !s) return s;
  }
  return file->close();
}

Status write_timesync(const VioRun& vio, const std::string& path) {
  auto file = io::TextFileWriter::create(path, "time-sync file");
  if (!file) return file.error();
  if (Status s = file->write_line("t_ns,gps_week,gps_tow_s"); !s) return s;
  for (const TimeSyncSample& t : vio.timesync) {
    const core::GpsTime n = t.time.normalized();
    if (Status s = file->write_line(format("%lld,%d,%.3f", static_cast<long long>(t.t_ns), n.week, n.tow_s)); !s) {
      return s;
    }
  }
  return file->close();
}

}  // namespace

Status write_simulation(const Simulation& sim, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Error{"cannot create output folder: " + ec.message(), dir, 0};
  const std::filesystem::path d(dir);
  if (Status s = io::write_rinex_obs((d / "rover.obs").string(), sim.rover.header, sim.rover.epochs); !s) return s;
  if (Status s = io::write_rinex_obs((d / "base.obs").string(), sim.base.header, sim.base.epochs); !s) return s;
  if (Status s = write_truth(sim, (d / "truth.csv").string()); !s) return s;
  if (Status s = write_city(sim, (d / "city.geojson").string()); !s) return s;
  if (!sim.scenario.vio.enabled) return Ok{};
  return write_vio_files(sim.vio, dir);
}

Status write_vio_files(const VioRun& vio, const std::string& dir) {
  const std::filesystem::path d(dir);
  if (Status s = write_vio(vio, (d / "vio.csv").string()); !s) return s;
  return write_timesync(vio, (d / "timesync.csv").string());
}

}  // namespace canyon::sim
