// `canyon simulate` (see simulate.hpp).

#include "canyon/app/simulate.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <Eigen/Geometry>

#include "canyon/app/scenario_config.hpp"
#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/sim/simulator.hpp"

namespace canyon::app {
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
       << scenario_to_yaml(sim->scenario, truth_section(*sim));
    if (!os) return Error{"cannot write scenario file", yaml_path, 0};
  }
  SimulateSummary summary;
  summary.rover_epochs = static_cast<int>(sim->rover.epochs.size());
  summary.base_epochs = static_cast<int>(sim->base.epochs.size());
  summary.rover_signal_epochs = sim->rover.signal_epochs;
  summary.nlos_fraction =
      sim->rover.signal_epochs > 0 ? double(sim->rover.nlos_signal_epochs) / sim->rover.signal_epochs : 0.0;
  summary.rover_losses = sim->rover.losses;
  summary.rover_slips = sim->rover.slips;
  summary.buildings = static_cast<int>(sim->city.buildings().size());
  summary.route_length_m = sim->trajectory.path().length_m();
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace canyon::app
