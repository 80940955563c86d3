#pragma once
// A 2.5-D city: building footprints (polygons) with flat roofs, street trees (crowns as vertical cylinders), and the
// geometry a GNSS signal meets on its way to the antenna: line of sight by ray casting, specular reflections off
// building walls, and the length of foliage crossed.
//
// Frames: N is the local ENU frame at the city origin (x east, y north, z up; the ground is the plane z = 0);
// G is the street-grid frame (x along the avenues). Rays: a satellite is so far away that its signal arrives as a
// plane wave from the unit direction u_N (antenna -> satellite).
//
// Line of sight: the ray p + s u (s > 0) is blocked when it crosses a building wall below the roof. Walls are
// found through a uniform grid of cells (Amanatides-Woo traversal), up to the horizontal distance at which the ray
// is above the tallest roof.
//
// Reflection off a vertical wall with outward unit normal n (horizontal) at distance d = (p - a) . n > 0 from the
// antenna, for a satellite in front of it (u . n > 0): mirroring the antenna across the wall plane gives the image
// p' = p - 2 d n; the specular point is P = p' + (d / (u . n)) u, which must lie on the wall (between its ends,
// between the ground and the roof); the reflected path is longer than the direct one by 2 d (u . n). It exists when
// the segments P -> p and P -> satellite are free of other buildings.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "canyon/sim/scenario.hpp"

namespace canyon::sim {

/// The street grid: street centrelines at x_G = i pitch_x and y_G = j pitch_y; blocks between them.
struct StreetGrid {
  double azimuth_rad = 0.0;  ///< of the grid x axis, clockwise from north
  double street_width_m = 20.0;
  double pitch_x_m = 120.0;  ///< block length + street width
  double pitch_y_m = 90.0;   ///< block width + street width

  [[nodiscard]] static StreetGrid from(const CityOptions& options);
  /// Rotation taking grid coordinates into ENU (east, north).
  [[nodiscard]] Eigen::Matrix2d R_NG() const;
  [[nodiscard]] Eigen::Vector2d to_N(const Eigen::Vector2d& p_G) const { return R_NG() * p_G; }
  [[nodiscard]] Eigen::Vector2d to_G(const Eigen::Vector2d& p_N) const { return R_NG().transpose() * p_N; }
};

/// Axis-aligned rectangle in the grid frame.
struct CityExtent {
  Eigen::Vector2d min_G = Eigen::Vector2d::Zero();
  Eigen::Vector2d max_G = Eigen::Vector2d::Zero();
  [[nodiscard]] bool contains_G(const Eigen::Vector2d& p_G) const {
    return (p_G.array() >= min_G.array()).all() && (p_G.array() <= max_G.array()).all();
  }
};

/// The extent of a city of blocks[0] x blocks[1] blocks centred on the origin (street centrelines at its edges).
[[nodiscard]] CityExtent blocks_extent(const std::vector<int>& blocks, const StreetGrid& grid);

struct Building {
  std::vector<Eigen::Vector2d> footprint_N_m;  ///< counter-clockwise polygon (east, north)
  double height_m = 0.0;                       ///< flat roof above the ground
};

struct Tree {
  Eigen::Vector2d center_N_m = Eigen::Vector2d::Zero();
  double radius_m = 3.0;
  double bottom_m = 3.0;  ///< lowest leaves
  double top_m = 12.0;
};

/// One wall: a footprint edge from a to b (counter-clockwise, so the outside is on the right).
struct Wall {
  Eigen::Vector2d a_N_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d b_N_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d normal_N = Eigen::Vector2d::Zero();  ///< outward unit normal
  double height_m = 0.0;
  int building = 0;
};

struct WallReflection {
  int wall = -1;
  Eigen::Vector3d point_N_m = Eigen::Vector3d::Zero();  ///< specular point on the wall
  double excess_m = 0.0;                                ///< reflected minus direct path length (m)
};

class City {
 public:
  City() = default;
  City(const StreetGrid& grid, const CityExtent& extent, std::vector<Building> buildings, std::vector<Tree> trees);

  /// True if a building blocks the ray from `p_N` towards direction `u_N` (unit; satellite at infinity).
  [[nodiscard]] bool direct_blocked(const Eigen::Vector3d& p_N, const Eigen::Vector3d& u_N) const;
  /// Length of tree crowns crossed by that ray (m).
  [[nodiscard]] double foliage_m(const Eigen::Vector3d& p_N, const Eigen::Vector3d& u_N) const;
  /// Walls whose front faces the point `p_N` within `max_distance_m` (horizontal), for wall_reflection().
  [[nodiscard]] std::vector<int> walls_facing(const Eigen::Vector3d& p_N, double max_distance_m) const;
  /// The specular wall reflection with the shortest excess path among `candidate_walls` whose path is free of
  /// buildings; nullopt if none.
  [[nodiscard]] std::optional<WallReflection> wall_reflection(const Eigen::Vector3d& p_N, const Eigen::Vector3d& u_N,
                                                              const std::vector<int>& candidate_walls) const;
  /// True if the horizontal point lies inside a building footprint.
  [[nodiscard]] bool inside_building(const Eigen::Vector2d& p_N) const;
  [[nodiscard]] bool contains(const Eigen::Vector2d& p_N) const { return extent_.contains_G(grid_.to_G(p_N)); }

  [[nodiscard]] const StreetGrid& grid() const { return grid_; }
  [[nodiscard]] const CityExtent& extent() const { return extent_; }
  [[nodiscard]] const std::vector<Building>& buildings() const { return buildings_; }
  [[nodiscard]] const std::vector<Tree>& trees() const { return trees_; }
  [[nodiscard]] const std::vector<Wall>& walls() const { return walls_; }
  [[nodiscard]] double tallest_m() const { return tallest_m_; }

 private:
  struct Cell {
    std::vector<int> walls;
    std::vector<int> trees;
  };
  [[nodiscard]] int cell_index(int ix, int iy) const { return iy * nx_ + ix; }
  void index_walls();
  void index_trees();
  /// Visits the cells a horizontal ray from `o` along unit `d` crosses up to distance `s_max`, in order, until
  /// `visit(cell)` returns true. Returns true if a visit returned true.
  template <typename Visit>
  bool traverse(const Eigen::Vector2d& o, const Eigen::Vector2d& d, double s_max, Visit&& visit) const;
  /// True if the straight segment from p to q (3-D) passes through a wall of a building other than `ignore`.
  [[nodiscard]] bool segment_blocked(const Eigen::Vector3d& p, const Eigen::Vector3d& q, int ignore) const;
  /// True if the ray p + s u (s > 0) passes through a wall of a building other than `ignore`.
  [[nodiscard]] bool ray_blocked(const Eigen::Vector3d& p, const Eigen::Vector3d& u, int ignore) const;

  StreetGrid grid_;
  CityExtent extent_;
  std::vector<Building> buildings_;
  std::vector<Tree> trees_;
  std::vector<Wall> walls_;
  double tallest_m_ = 0.0;
  double tallest_tree_m_ = 0.0;
  // Uniform grid over the ENU bounding box of the extent.
  Eigen::Vector2d grid_min_N_ = Eigen::Vector2d::Zero();
  double cell_m_ = 16.0;
  int nx_ = 0;
  int ny_ = 0;
  std::vector<Cell> cells_;
};

/// Footprints and trees for the blocks of `extent` (see CityOptions, TreeOptions): each block is split into two
/// rows of lots back to back, each lot a rectangular building with a height from a normal distribution clipped to
/// [height_min_m, height_max_m], or empty with gap_probability. Trees stand along every street at
/// `facade_offset_m` from the facades.
[[nodiscard]] City generate_city(const CityOptions& city, const TreeOptions& trees, const CityExtent& extent,
                                 std::uint64_t seed);

}  // namespace canyon::sim
