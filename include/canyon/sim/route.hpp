#pragma once
// The pedestrian's walk: a horizontal path in the city's ENU frame (straight segments joined by circular arcs at
// corners), walked at constant speed, with the head-worn antenna above it.
//
// Generated walks follow the street grid: a random walk over intersections (straight on, or a left or right turn
// with `turn_probability`, never back), on the right-hand sidewalk `sidewalk_offset_m` from the facades, crossing
// streets at intersections. An explicit route (waypoints) is walked to its end and back, as often as the duration
// needs.

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/result.hpp"
#include "canyon/sim/city.hpp"
#include "canyon/sim/scenario.hpp"

namespace canyon::sim {

class Path {
 public:
  /// Path through `points_N` (at least 2, consecutive points distinct); corners turning by less than 150 deg are
  /// rounded with `turn_radius_m` (limited to what the neighbouring segments allow); sharper ones are kept.
  static Path through(const std::vector<Eigen::Vector2d>& points_N, double turn_radius_m);

  [[nodiscard]] double length_m() const { return length_m_; }
  /// Position at arc length s (clamped to [0, length]).
  [[nodiscard]] Eigen::Vector2d position_N(double s_m) const;
  /// Unit direction of travel at arc length s.
  [[nodiscard]] Eigen::Vector2d direction_N(double s_m) const;
  /// The corner points the path was built from.
  [[nodiscard]] const std::vector<Eigen::Vector2d>& points_N() const { return points_N_; }

 private:
  struct Piece {
    double s0_m = 0.0;  ///< arc length at the start of the piece
    double length_m = 0.0;
    Eigen::Vector2d start_N = Eigen::Vector2d::Zero();
    Eigen::Vector2d direction_N = Eigen::Vector2d::Zero();  ///< at the start
    double curvature_1pm = 0.0;                             ///< 0: straight; > 0: left turn
  };
  [[nodiscard]] const Piece& piece_at(double s_m) const;

  std::vector<Piece> pieces_;
  std::vector<Eigen::Vector2d> points_N_;
  double length_m_ = 0.0;
};

/// Grid intersections of a random walk of at least `length_m` from intersection (0, 0); with `extent` set, the walk
/// stays on streets strictly inside it. Grid coordinates of the walking line (right-hand sidewalk) are returned.
[[nodiscard]] std::vector<Eigen::Vector2d> random_walk_G(const RouteOptions& route, const StreetGrid& grid,
                                                         double length_m, const CityExtent* extent, std::uint64_t seed);

/// The antenna trajectory of a scenario: position (ENU, z above the ground) and walking direction at time t (s since
/// the start).
class Trajectory {
 public:
  Trajectory() = default;
  Trajectory(Path path, const RouteOptions& options) : path_(std::move(path)), options_(options) {}

  [[nodiscard]] Eigen::Vector3d antenna_N(double t_s) const;
  [[nodiscard]] Eigen::Vector3d velocity_N(double t_s) const;
  /// Unit walking direction (horizontal) at t.
  [[nodiscard]] Eigen::Vector2d heading_N(double t_s) const;
  [[nodiscard]] const Path& path() const { return path_; }

 private:
  /// Arc length walked at t (back and forth along the path).
  [[nodiscard]] double arc_length(double t_s, double* direction_sign = nullptr) const;

  Path path_;
  RouteOptions options_;
};

}  // namespace canyon::sim
