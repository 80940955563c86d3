#include "canyon/core/geodesy.hpp"

#include <algorithm>
#include <cmath>

#include "canyon/core/constants.hpp"

namespace canyon::core {

Eigen::Vector3d geodetic_to_ecef(const Geodetic& g) {
  const double sin_lat = std::sin(g.lat_rad);
  const double cos_lat = std::cos(g.lat_rad);
  const double n = kWgs84SemiMajorM / std::sqrt(1.0 - kWgs84EccentricitySq * sin_lat * sin_lat);
  return {(n + g.height_m) * cos_lat * std::cos(g.lon_rad), (n + g.height_m) * cos_lat * std::sin(g.lon_rad),
          (n * (1.0 - kWgs84EccentricitySq) + g.height_m) * sin_lat};
}

Geodetic ecef_to_geodetic(const Eigen::Vector3d& p_E) {
  // Fixed-point iteration on z: converges to < 1e-4 mm within a few iterations for all terrestrial and orbital
  // points; capped so that a degenerate input cannot loop.
  const double r2 = p_E.x() * p_E.x() + p_E.y() * p_E.y();
  double z = p_E.z();
  double zk = 0.0;
  double n = kWgs84SemiMajorM;
  for (int i = 0; i < 20 && std::abs(z - zk) >= 1e-6; ++i) {
    zk = z;
    const double sin_lat = z / std::sqrt(r2 + z * z);
    n = kWgs84SemiMajorM / std::sqrt(1.0 - kWgs84EccentricitySq * sin_lat * sin_lat);
    z = p_E.z() + n * kWgs84EccentricitySq * sin_lat;
  }
  Geodetic g;
  if (r2 > 1e-12) {
    g.lat_rad = std::atan(z / std::sqrt(r2));
    g.lon_rad = std::atan2(p_E.y(), p_E.x());
  } else {
    g.lat_rad = p_E.z() > 0.0 ? kPi / 2.0 : -kPi / 2.0;
    g.lon_rad = 0.0;
  }
  g.height_m = std::sqrt(r2 + z * z) - n;
  return g;
}

Eigen::Matrix3d rotation_enu_from_ecef(const Geodetic& origin) {
  const double sl = std::sin(origin.lat_rad);
  const double cl = std::cos(origin.lat_rad);
  const double so = std::sin(origin.lon_rad);
  const double co = std::cos(origin.lon_rad);
  Eigen::Matrix3d R_NE;
  R_NE << -so, co, 0.0, -sl * co, -sl * so, cl, cl * co, cl * so, sl;
  return R_NE;
}

Eigen::Vector3d ecef_to_enu(const Eigen::Vector3d& d_E, const Geodetic& origin) {
  return rotation_enu_from_ecef(origin) * d_E;
}

Eigen::Vector3d enu_to_ecef(const Eigen::Vector3d& d_N, const Geodetic& origin) {
  return rotation_enu_from_ecef(origin).transpose() * d_N;
}

AzEl azimuth_elevation_from_enu(const Eigen::Vector3d& d_N) {
  const Eigen::Vector3d los_N = d_N.normalized();
  AzEl result;
  const double horizontal = los_N.x() * los_N.x() + los_N.y() * los_N.y();
  result.azimuth_rad = horizontal < 1e-12 ? 0.0 : std::atan2(los_N.x(), los_N.y());
  if (result.azimuth_rad < 0.0) {
    result.azimuth_rad += 2.0 * kPi;
  }
  result.elevation_rad = std::asin(std::clamp(los_N.z(), -1.0, 1.0));
  return result;
}

double elevation_from_enu(const Eigen::Vector3d& d_N) {
  return std::asin(std::clamp(d_N.normalized().z(), -1.0, 1.0));  // as in azimuth_elevation_from_enu
}

namespace {
/// No position yet (the Earth's centre): every satellite at zenith.
bool at_earth_centre(const Eigen::Vector3d& p_E_rcv, const Geodetic& rcv) {
  return rcv.height_m <= -kWgs84SemiMajorM + 1.0 || p_E_rcv.norm() < 1.0;
}
}  // namespace

AzEl azimuth_elevation(const Eigen::Vector3d& p_E_rcv, const Geodetic& rcv, const Eigen::Vector3d& p_E_sat) {
  if (at_earth_centre(p_E_rcv, rcv)) return AzEl{0.0, kPi / 2.0};
  return azimuth_elevation_from_enu(ecef_to_enu(p_E_sat - p_E_rcv, rcv));
}

double elevation_rad(const Eigen::Vector3d& p_E_rcv, const Geodetic& rcv, const Eigen::Matrix3d& R_NE,
                     const Eigen::Vector3d& p_E_sat) {
  if (at_earth_centre(p_E_rcv, rcv)) return kPi / 2.0;
  return elevation_from_enu(R_NE * (p_E_sat - p_E_rcv));
}

}  // namespace canyon::core
