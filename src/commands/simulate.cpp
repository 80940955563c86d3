// `canyon simulate` (see simulate.hpp).

#include "canyon/commands/simulate.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string_view>

#include <Eigen/Geometry>

#include "canyon/config/scenario_config.hpp"
#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/io/text_reader.hpp"
#include "canyon/sim/simulator.hpp"

namespace canyon::commands {
namespace {

std::string fmt(const char* format, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, v);
  return buffer;
}

std::string vec(const Eigen::Vector3d& v, const char* format = "%.4f") {
  return std::string("[") + fmt(format, v.x()) + ", " + fmt(format, v.y()) + ", " + fmt(format, v.z()) + "]";
}

/// The `truth:` section of scenario.yaml (indented by two spaces).
std::string truth_section(const sim::Simulation& sim) {
  const sim::Scenario& sc = sim.scenario;
  std::string t;
  const auto line = [&t](const std::string& key, const std::string& value) {
    t.append("  ").append(key).append(": ").append(value).append("\n");
  };
  line("base_position_E_m", vec(sim.base_p_E_m));
  const core::Geodetic base = core::ecef_to_geodetic(sim.base_p_E_m);
  line("base_llh", std::string("[") + fmt("%.9f", base.lat_rad * core::kRadToDeg) + ", " +
                       fmt("%.9f", base.lon_rad * core::kRadToDeg) + ", " + fmt("%.4f", base.height_m) + "]");
  line("baseline_m", fmt("%.1f", (sim.base_p_E_m - sim.truth.front().p_E_m).norm()));
  line("rover_start_E_m", vec(sim.truth.front().p_E_m));
  line("rover_clock_offset_s", fmt("%.12e", sim.rover.clock_offset_s));
  line("rover_clock_drift_sps", fmt("%.6e", sim.rover.clock_drift_sps));
  line("base_clock_offset_s", fmt("%.12e", sim.base.clock_offset_s));
  line("base_clock_drift_sps", fmt("%.6e", sim.base.clock_drift_sps));
  line("route_length_m", fmt("%.1f", sim.trajectory.path().length_m()));
  double sum_m = 0.0, max_m = 0.0;
  for (const sim::Building& b : sim.city.buildings()) {
    sum_m += b.height_m;
    max_m = std::max(max_m, b.height_m);
  }
  const auto n = static_cast<double>(sim.city.buildings().size());
  line("buildings", std::to_string(sim.city.buildings().size()));
  line("building_height_mean_m", fmt("%.2f", n > 0 ? sum_m / n : 0.0));
  line("building_height_max_m", fmt("%.2f", max_m));
  line("trees", std::to_string(sim.city.trees().size()));
  line("rover_signal_epochs", std::to_string(sim.rover.signal_epochs));
  line("rover_nlos_signal_epochs", std::to_string(sim.rover.nlos_signal_epochs));
  line("rover_line_of_sight_epochs", std::to_string(sim.rover.line_of_sight_epochs));  // >= 5 LOS phase satellites
  line("rover_lock_losses", std::to_string(sim.rover.losses));
  line("rover_slips", std::to_string(sim.rover.slips));
  // VIO: the lever arm, the odometry frame (gravity-aligned, origin at the IMU's start, see sim/vio.hpp), the device
  // clock and how far the VIO drifted.
  line("t_IA_m", vec(sc.vio.t_IA_m));
  if (sc.vio.enabled && !sim.vio.poses.empty()) {
    const sim::Pose& T_EO = sim.vio.T_EO;
    const Eigen::Quaterniond q = T_EO.q.normalized();
    line("T_EO", "{q_xyzw: [" + fmt("%.12f", q.x()) + ", " + fmt("%.12f", q.y()) + ", " + fmt("%.12f", q.z()) + ", " +
                     fmt("%.12f", q.w()) + "], p_m: " + vec(T_EO.p) + "}");
    line("device_clock", "{offset_s: " + fmt("%.9f", sc.vio.device_clock_offset_s) +
                             ", drift_ppm: " + fmt("%.6f", sc.vio.device_clock_drift_ppm) + "}");
    const sim::VioSample& last = sim.vio.poses.back();
    line("vio_final_position_error_m", fmt("%.3f", (last.T_OI.p - last.T_OI_true.p).norm()));
    line("vio_final_position_sigma_m", fmt("%.3f", std::sqrt(last.covariance.topLeftCorner<3, 3>().trace())));
  }
  return t;
}

}  // namespace

Result<SimulateSummary> run_simulate(const sim::Scenario& scenario, const std::string& out_dir) {
  const auto start = std::chrono::steady_clock::now();
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return Error{"cannot create output folder: " + ec.message(), out_dir, 0};
  const std::filesystem::path dir(out_dir);
  auto sim = sim::simulate(scenario, (dir / "nav.rnx").string());
  if (!sim) return sim.error();
  if (Status s = sim::write_simulation(*sim, out_dir); !s) return s.error();
  const std::string yaml_path = (dir / "scenario.yaml").string();
  {
    std::ofstream os(yaml_path, std::ios::binary);
    os << "# Written by canyon simulate: the effective scenario (every key) and, under truth:, the true parameters.\n"
       << config::scenario_to_yaml(sim->scenario, truth_section(*sim));
    if (!os) return Error{"cannot write scenario file", yaml_path, 0};
  }
  SimulateSummary summary;
  summary.rover_epochs = static_cast<int>(sim->rover.epochs.size());
  summary.base_epochs = static_cast<int>(sim->base.epochs.size());
  summary.rover_signal_epochs = sim->rover.signal_epochs;
  summary.nlos_fraction =
      sim->rover.signal_epochs > 0 ? double(sim->rover.nlos_signal_epochs) / sim->rover.signal_epochs : 0.0;
  summary.line_of_sight_epochs = sim->rover.line_of_sight_epochs;
  summary.rover_losses = sim->rover.losses;
  summary.rover_slips = sim->rover.slips;
  summary.buildings = static_cast<int>(sim->city.buildings().size());
  summary.route_length_m = sim->trajectory.path().length_m();
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

namespace {

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    out.push_back(
        io::trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) return out;
    start = comma + 1;
  }
}

/// R_EI from Spirent's roll, pitch, yaw (body x forward, y right, z down against north-east-down) at p_E.
Eigen::Quaterniond spirent_attitude(const Eigen::Vector3d& p_E, double roll_deg, double pitch_deg, double yaw_deg) {
  const Eigen::Matrix3d R_EN = core::rotation_enu_from_ecef(core::ecef_to_geodetic(p_E)).transpose();  // ENU -> E
  Eigen::Matrix3d R_enu_ned;
  R_enu_ned << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  const Eigen::Matrix3d R_ned_b = (Eigen::AngleAxisd(yaw_deg * core::kDegToRad, Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(pitch_deg * core::kDegToRad, Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(roll_deg * core::kDegToRad, Eigen::Vector3d::UnitX()))
                                      .toRotationMatrix();
  const Eigen::Matrix3d R_b_flu = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();  // canyon's I: x fwd, y left, z up
  return Eigen::Quaterniond(R_EN * R_enu_ned * R_ned_b * R_b_flu).normalized();
}

}  // namespace

Result<std::vector<sim::SixDofSample>> read_six_dof_truth(const std::string& path) {
  auto opened = io::TextReader::open(path);
  if (!opened) return opened.error();
  io::TextReader& reader = *opened;
  const auto header_line = reader.next_line();
  if (!header_line) return Error{"empty truth file", path, 1};
  const std::vector<std::string_view> header = split_fields(*header_line);
  const auto column = [&header](std::string_view name) -> int {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return static_cast<int>(i);
    }
    return -1;
  };
  const bool spirent = column("GpsCycle") >= 0;
  const std::vector<std::string_view> names =
      spirent ? std::vector<std::string_view>{"GpsCycle",       "GpsWeek",        "GpsToW [s]",
                                              "Pos ECEF X [m]", "Pos ECEF Y [m]", "Pos ECEF Z [m]",
                                              "Roll [deg]",     "Pitch [deg]",    "Yaw [deg]"}
              : std::vector<std::string_view>{"gps_week", "gps_tow_s", "x", "y", "z", "qx", "qy", "qz", "qw"};
  std::vector<int> index;
  for (const std::string_view n : names) {
    index.push_back(column(n));
    if (index.back() < 0) {
      return reader.error("not a 6-DoF truth: no column '" + std::string(n) +
                          "' (canyon truth.csv with qx,qy,qz,qw, or a Spirent PVA CSV with roll, pitch, yaw)");
    }
  }
  std::vector<sim::SixDofSample> samples;
  while (const auto line = reader.next_line()) {
    if (io::trim(*line).empty()) continue;
    const std::vector<std::string_view> fields = split_fields(*line);
    std::array<double, 9> v{};
    for (std::size_t i = 0; i < index.size(); ++i) {
      const auto k = static_cast<std::size_t>(index[i]);
      const auto value = k < fields.size() ? io::parse_double(fields[k]) : std::nullopt;
      if (!value || !std::isfinite(*value))
        return reader.error("field '" + std::string(names[i]) + "' is not a number");
      v[i] = *value;
    }
    sim::SixDofSample s;
    if (spirent) {
      const int week = static_cast<int>(std::lround(v[0])) * 1024 + static_cast<int>(std::lround(v[1]));
      s.time = core::GpsTime{week, v[2]}.normalized();
      s.p_E_A_m = Eigen::Vector3d(v[3], v[4], v[5]);
      s.q_EI = spirent_attitude(s.p_E_A_m, v[6], v[7], v[8]);
    } else {
      s.time = core::GpsTime{static_cast<int>(std::lround(v[0])), v[1]}.normalized();
      s.p_E_A_m = Eigen::Vector3d(v[2], v[3], v[4]);
      const Eigen::Quaterniond q(v[8], v[5], v[6], v[7]);
      if (!(std::abs(q.norm() - 1.0) < 0.01)) return reader.error("qx,qy,qz,qw is not a unit quaternion");
      s.q_EI = q.normalized();
    }
    if (!samples.empty() && !(s.time - samples.back().time > 0.0)) {
      return reader.error("time does not increase");
    }
    samples.push_back(s);
  }
  if (const auto& e = reader.read_error()) return Error{"read error: " + *e, path, reader.line_number()};
  if (samples.size() < 2) return Error{"a 6-DoF truth needs at least two samples", path, reader.line_number()};
  return samples;
}

Result<VioFromTruthSummary> run_vio_from_truth(const std::string& truth_path, const sim::VioOptions& vio,
                                               std::uint64_t seed, const std::string& out_dir) {
  const auto start = std::chrono::steady_clock::now();
  auto truth = read_six_dof_truth(truth_path);
  if (!truth) return truth.error();
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return Error{"cannot create output folder: " + ec.message(), out_dir, 0};
  const sim::VioRun run = sim::simulate_vio_from_truth(vio, *truth, seed);
  if (run.poses.size() < 2) return Error{"the truth spans less than one VIO period", truth_path, 0};
  if (Status s = sim::write_vio_files(run, out_dir); !s) return s.error();
  const std::string yaml_path = (std::filesystem::path(out_dir) / "vio_truth.yaml").string();
  {
    std::ofstream os(yaml_path, std::ios::binary);
    const Eigen::Quaterniond q = run.T_EO.q.normalized();
    const sim::VioSample& last = run.poses.back();
    os << "# Written by canyon simulate --vio-from-truth: the true parameters of vio.csv and timesync.csv.\n"
       << "truth_file: " << truth_path << "\n"
       << "seed: " << seed << "\n"
       << "t_IA_m: " << vec(vio.t_IA_m) << "\n"
       << "T_EO: {q_xyzw: [" << fmt("%.12f", q.x()) << ", " << fmt("%.12f", q.y()) << ", " << fmt("%.12f", q.z())
       << ", " << fmt("%.12f", q.w()) << "], p_m: " << vec(run.T_EO.p) << "}\n"
       << "device_clock: {offset_s: " << fmt("%.9f", vio.device_clock_offset_s)
       << ", drift_ppm: " << fmt("%.6f", vio.device_clock_drift_ppm) << "}\n"
       << "vio_final_position_error_m: " << fmt("%.3f", (last.T_OI.p - last.T_OI_true.p).norm()) << "\n";
    if (!os) return Error{"cannot write", yaml_path, 0};
  }
  VioFromTruthSummary summary;
  summary.poses = static_cast<int>(run.poses.size());
  summary.timesync_pairs = static_cast<int>(run.timesync.size());
  summary.duration_s = truth->back().time - truth->front().time;
  summary.final_position_error_m = (run.poses.back().T_OI.p - run.poses.back().T_OI_true.p).norm();
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace canyon::commands
