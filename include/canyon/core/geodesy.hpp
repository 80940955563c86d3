#pragma once
// WGS84 geodesy: ECEF (E) <-> geodetic, local ENU (N), elevation and azimuth.
// Angles in radians, heights above the ellipsoid in metres.

#include <Eigen/Core>

namespace canyon::core {

struct Geodetic {
  double lat_rad = 0.0;
  double lon_rad = 0.0;
  double height_m = 0.0;  ///< above the WGS84 ellipsoid
};

[[nodiscard]] Eigen::Vector3d geodetic_to_ecef(const Geodetic& g);
/// Exact to well below a millimetre anywhere from the Earth's centre region to GEO altitude; the origin maps to
/// {0, 0, -a}.
[[nodiscard]] Geodetic ecef_to_geodetic(const Eigen::Vector3d& p_E);

/// Rotation R_NE taking ECEF vectors into the local east-north-up frame at `origin`.
[[nodiscard]] Eigen::Matrix3d rotation_enu_from_ecef(const Geodetic& origin);
/// ENU coordinates of vector `d_E` (an ECEF difference) at `origin`.
[[nodiscard]] Eigen::Vector3d ecef_to_enu(const Eigen::Vector3d& d_E, const Geodetic& origin);
[[nodiscard]] Eigen::Vector3d enu_to_ecef(const Eigen::Vector3d& d_N, const Geodetic& origin);

struct AzEl {
  double azimuth_rad = 0.0;    ///< [0, 2 pi), clockwise from north
  double elevation_rad = 0.0;  ///< [-pi/2, pi/2]
};
/// Azimuth and elevation of a direction given in local ENU (need not be unit length, must not be zero).
[[nodiscard]] AzEl azimuth_elevation_from_enu(const Eigen::Vector3d& d_N);

/// The elevation of azimuth_elevation_from_enu(d_N), without the azimuth (one atan2 less).
[[nodiscard]] double elevation_from_enu(const Eigen::Vector3d& d_N);

/// Azimuth and elevation of a satellite at p_E_sat seen from a receiver at p_E_rcv (geodetic `rcv`). A receiver at
/// the Earth's centre (no position yet) sees every satellite at 90 deg elevation, as RTKLIB assumes.
[[nodiscard]] AzEl azimuth_elevation(const Eigen::Vector3d& p_E_rcv, const Geodetic& rcv,
                                     const Eigen::Vector3d& p_E_sat);

/// azimuth_elevation(p_E_rcv, rcv, p_E_sat).elevation_rad, with R_NE = rotation_enu_from_ecef(rcv) given: for many
/// satellites seen from one receiver (the rotation's sines and cosines once, no azimuth).
[[nodiscard]] double elevation_rad(const Eigen::Vector3d& p_E_rcv, const Geodetic& rcv, const Eigen::Matrix3d& R_NE,
                                   const Eigen::Vector3d& p_E_sat);

}  // namespace canyon::core
