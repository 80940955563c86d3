// 2.5-D city model, ray casting and reflections (see city.hpp).

#include "canyon/sim/city.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "canyon/core/constants.hpp"
#include "canyon/sim/random.hpp"

namespace canyon::sim {
namespace {

constexpr double kEpsM = 1e-6;
constexpr double kCellM = 16.0;
constexpr std::uint64_t kCityStream = 0xC17E;

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// Intersection of the horizontal ray o + s d with segment a-b: (s, t) with t in [0, 1] along the segment.
std::optional<std::pair<double, double>> ray_segment(const Eigen::Vector2d& o, const Eigen::Vector2d& d,
                                                     const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = b - a;
  const double denom = cross(d, e);
  if (std::abs(denom) < 1e-12) return std::nullopt;
  const Eigen::Vector2d ao = a - o;
  const double s = cross(ao, e) / denom;
  const double t = cross(ao, d) / denom;
  if (t < 0.0 || t > 1.0) return std::nullopt;
  return std::make_pair(s, t);
}

double distance_to_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = b - a;
  const double t = std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return (a + t * e - p).norm();
}

bool point_in_polygon(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& poly) {
  bool inside = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2d& a = poly[i];
    const Eigen::Vector2d& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

}  // namespace

StreetGrid StreetGrid::from(const CityOptions& options) {
  StreetGrid g;
  g.azimuth_rad = options.grid_azimuth_deg * core::kDegToRad;
  g.street_width_m = options.street_width_m;
  g.pitch_x_m = options.block_length_m + options.street_width_m;
  g.pitch_y_m = options.block_width_m + options.street_width_m;
  return g;
}

Eigen::Matrix2d StreetGrid::R_NG() const {
  // Grid x along azimuth az: (sin az, cos az) in (east, north); grid y 90 deg to its left: (-cos az, sin az).
  Eigen::Matrix2d r;
  r << std::sin(azimuth_rad), -std::cos(azimuth_rad), std::cos(azimuth_rad), std::sin(azimuth_rad);
  return r;
}

CityExtent blocks_extent(const std::vector<int>& blocks, const StreetGrid& grid) {
  CityExtent e;
  const Eigen::Vector2d pitch(grid.pitch_x_m, grid.pitch_y_m);
  e.min_G = Eigen::Vector2d(-(blocks.at(0) / 2), -(blocks.at(1) / 2)).cwiseProduct(pitch);
  e.max_G = e.min_G + Eigen::Vector2d(blocks.at(0), blocks.at(1)).cwiseProduct(pitch);
  return e;
}

City::City(const StreetGrid& grid, const CityExtent& extent, std::vector<Building> buildings, std::vector<Tree> trees)
    : grid_(grid), extent_(extent), buildings_(std::move(buildings)), trees_(std::move(trees)) {
  for (int b = 0; b < static_cast<int>(buildings_.size()); ++b) {
    const Building& building = buildings_[static_cast<std::size_t>(b)];
    tallest_m_ = std::max(tallest_m_, building.height_m);
    const auto& poly = building.footprint_N_m;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      Wall w;
      w.a_N_m = poly[i];
      w.b_N_m = poly[(i + 1) % poly.size()];
      const Eigen::Vector2d e = (w.b_N_m - w.a_N_m).normalized();
      w.normal_N = Eigen::Vector2d(e.y(), -e.x());  // right of a counter-clockwise edge: outward
      w.height_m = building.height_m;
      w.building = b;
      walls_.push_back(w);
    }
  }
  for (const Tree& t : trees_) tallest_tree_m_ = std::max(tallest_tree_m_, t.top_m);
  // ENU bounding box of the extent's corners.
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d hi = -lo;
  for (const Eigen::Vector2d& c : {extent_.min_G, Eigen::Vector2d(extent_.max_G.x(), extent_.min_G.y()), extent_.max_G,
                                   Eigen::Vector2d(extent_.min_G.x(), extent_.max_G.y())}) {
    lo = lo.cwiseMin(grid_.to_N(c));
    hi = hi.cwiseMax(grid_.to_N(c));
  }
  cell_m_ = kCellM;
  grid_min_N_ = lo - Eigen::Vector2d::Constant(cell_m_);
  nx_ = static_cast<int>(std::ceil((hi.x() - grid_min_N_.x()) / cell_m_)) + 1;
  ny_ = static_cast<int>(std::ceil((hi.y() - grid_min_N_.y()) / cell_m_)) + 1;
  cells_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), Cell{});
  index_walls();
  index_trees();
}

void City::index_walls() {
  for (int w = 0; w < static_cast<int>(walls_.size()); ++w) {
    const Wall& wall = walls_[static_cast<std::size_t>(w)];
    const Eigen::Vector2d lo = (wall.a_N_m.cwiseMin(wall.b_N_m) - grid_min_N_) / cell_m_;
    const Eigen::Vector2d hi = (wall.a_N_m.cwiseMax(wall.b_N_m) - grid_min_N_) / cell_m_;
    for (int iy = std::max(0, int(std::floor(lo.y()))); iy <= std::min(ny_ - 1, int(std::floor(hi.y()))); ++iy) {
      for (int ix = std::max(0, int(std::floor(lo.x()))); ix <= std::min(nx_ - 1, int(std::floor(hi.x()))); ++ix) {
        // Keep only cells the wall really crosses (walls of a rotated grid are diagonal in ENU).
        const Eigen::Vector2d centre = grid_min_N_ + cell_m_ * Eigen::Vector2d(ix + 0.5, iy + 0.5);
        if (distance_to_segment(centre, wall.a_N_m, wall.b_N_m) > cell_m_ * 0.7072) continue;
        cells_[static_cast<std::size_t>(cell_index(ix, iy))].walls.push_back(w);
      }
    }
  }
}

void City::index_trees() {
  for (int t = 0; t < static_cast<int>(trees_.size()); ++t) {
    const Tree& tree = trees_[static_cast<std::size_t>(t)];
    const Eigen::Vector2d lo = (tree.center_N_m - grid_min_N_).array() / cell_m_ - tree.radius_m / cell_m_;
    const Eigen::Vector2d hi = (tree.center_N_m - grid_min_N_).array() / cell_m_ + tree.radius_m / cell_m_;
    for (int iy = std::max(0, int(std::floor(lo.y()))); iy <= std::min(ny_ - 1, int(std::floor(hi.y()))); ++iy) {
      for (int ix = std::max(0, int(std::floor(lo.x()))); ix <= std::min(nx_ - 1, int(std::floor(hi.x()))); ++ix) {
        cells_[static_cast<std::size_t>(cell_index(ix, iy))].trees.push_back(t);
      }
    }
  }
}

template <typename Visit>
bool City::traverse(const Eigen::Vector2d& o, const Eigen::Vector2d& d, double s_max, Visit&& visit) const {
  // Clip the ray to the cell grid's box.
  const Eigen::Vector2d box_lo = grid_min_N_;
  const Eigen::Vector2d box_hi = grid_min_N_ + cell_m_ * Eigen::Vector2d(nx_, ny_);
  double s0 = 0.0, s1 = s_max;
  for (int k = 0; k < 2; ++k) {
    if (std::abs(d(k)) < 1e-15) {
      if (o(k) < box_lo(k) || o(k) > box_hi(k)) return false;
      continue;
    }
    double a = (box_lo(k) - o(k)) / d(k), b = (box_hi(k) - o(k)) / d(k);
    if (a > b) std::swap(a, b);
    s0 = std::max(s0, a);
    s1 = std::min(s1, b);
  }
  if (s0 > s1) return false;
  const Eigen::Vector2d start = (o + s0 * d - grid_min_N_) / cell_m_;
  int ix = std::clamp(static_cast<int>(std::floor(start.x())), 0, nx_ - 1);
  int iy = std::clamp(static_cast<int>(std::floor(start.y())), 0, ny_ - 1);
  const int step_x = d.x() > 0.0 ? 1 : -1, step_y = d.y() > 0.0 ? 1 : -1;
  const double inf = std::numeric_limits<double>::infinity();
  const auto boundary = [&](int i, int step, int k) {
    return (grid_min_N_(k) + cell_m_ * (i + (step > 0 ? 1 : 0)) - o(k)) / d(k);
  };
  double t_max_x = std::abs(d.x()) < 1e-15 ? inf : boundary(ix, step_x, 0);
  double t_max_y = std::abs(d.y()) < 1e-15 ? inf : boundary(iy, step_y, 1);
  const double t_delta_x = std::abs(d.x()) < 1e-15 ? inf : cell_m_ / std::abs(d.x());
  const double t_delta_y = std::abs(d.y()) < 1e-15 ? inf : cell_m_ / std::abs(d.y());
  while (true) {
    if (visit(cells_[static_cast<std::size_t>(cell_index(ix, iy))])) return true;
    if (std::min(t_max_x, t_max_y) > s1) return false;
    if (t_max_x < t_max_y) {
      ix += step_x;
      t_max_x += t_delta_x;
      if (ix < 0 || ix >= nx_) return false;
    } else {
      iy += step_y;
      t_max_y += t_delta_y;
      if (iy < 0 || iy >= ny_) return false;
    }
  }
}

bool City::ray_blocked(const Eigen::Vector3d& p, const Eigen::Vector3d& u, int ignore) const {
  const double h = std::hypot(u.x(), u.y());
  if (h < 1e-12) return false;  // straight up
  if (p.z() >= tallest_m_ && u.z() >= 0.0) return false;
  const Eigen::Vector2d o = p.head<2>();
  const Eigen::Vector2d d = u.head<2>() / h;
  const double tan_el = u.z() / h;
  const double s_max = tan_el > 0.0 ? (tallest_m_ - p.z()) / tan_el : std::numeric_limits<double>::max();
  return traverse(o, d, s_max, [&](const Cell& cell) {
    for (const int w : cell.walls) {
      const Wall& wall = walls_[static_cast<std::size_t>(w)];
      if (wall.building == ignore) continue;
      const auto hit = ray_segment(o, d, wall.a_N_m, wall.b_N_m);
      if (!hit || hit->first <= kEpsM) continue;
      const double z = p.z() + hit->first * tan_el;
      if (z < wall.height_m && z > 0.0) return true;
    }
    return false;
  });
}

bool City::segment_blocked(const Eigen::Vector3d& p, const Eigen::Vector3d& q, int ignore) const {
  const Eigen::Vector2d o = p.head<2>();
  const Eigen::Vector2d dq = q.head<2>() - o;
  const double length = dq.norm();
  if (length < 1e-9) return false;
  const Eigen::Vector2d d = dq / length;
  const double slope = (q.z() - p.z()) / length;
  return traverse(o, d, length, [&](const Cell& cell) {
    for (const int w : cell.walls) {
      const Wall& wall = walls_[static_cast<std::size_t>(w)];
      if (wall.building == ignore) continue;
      const auto hit = ray_segment(o, d, wall.a_N_m, wall.b_N_m);
      if (!hit || hit->first <= kEpsM || hit->first >= length - kEpsM) continue;
      if (p.z() + hit->first * slope < wall.height_m) return true;
    }
    return false;
  });
}

bool City::direct_blocked(const Eigen::Vector3d& p_N, const Eigen::Vector3d& u_N) const {
  return ray_blocked(p_N, u_N, -1);
}

double City::foliage_m(const Eigen::Vector3d& p_N, const Eigen::Vector3d& u_N) const {
  if (trees_.empty()) return 0.0;
  const double h = std::hypot(u_N.x(), u_N.y());
  const Eigen::Vector2d o = p_N.head<2>();
  const double z0 = p_N.z();
  double total_m = 0.0;
  if (h < 1e-12) {  // straight up: only a crown right above the antenna
    for (const Tree& t : trees_) {
      if ((t.center_N_m - o).norm() < t.radius_m) total_m += std::max(0.0, t.top_m - std::max(t.bottom_m, z0));
    }
    return total_m;
  }
  const Eigen::Vector2d d = u_N.head<2>() / h;
  const double tan_el = u_N.z() / h;
  if (tan_el <= 0.0) return 0.0;
  const double s_max = (tallest_tree_m_ - z0) / tan_el;
  if (s_max <= 0.0) return 0.0;
  std::vector<int> seen;
  traverse(o, d, s_max, [&](const Cell& cell) {
    for (const int i : cell.trees) {
      if (std::find(seen.begin(), seen.end(), i) != seen.end()) continue;
      seen.push_back(i);
      const Tree& t = trees_[static_cast<std::size_t>(i)];
      const Eigen::Vector2d f = o - t.center_N_m;
      const double b = f.dot(d);
      const double disc = b * b - (f.squaredNorm() - t.radius_m * t.radius_m);
      if (disc <= 0.0) continue;
      const double root = std::sqrt(disc);
      const double s_in = std::max({-b - root, (t.bottom_m - z0) / tan_el, 0.0});
      const double s_out = std::min(-b + root, (t.top_m - z0) / tan_el);
      if (s_out > s_in) total_m += (s_out - s_in) * std::sqrt(1.0 + tan_el * tan_el);
    }
    return false;
  });
  return total_m;
}

std::vector<int> City::walls_facing(const Eigen::Vector3d& p_N, double max_distance_m) const {
  std::vector<int> out;
  const Eigen::Vector2d p = p_N.head<2>();
  const Eigen::Vector2d lo = (p - grid_min_N_).array() / cell_m_ - max_distance_m / cell_m_;
  const Eigen::Vector2d hi = (p - grid_min_N_).array() / cell_m_ + max_distance_m / cell_m_;
  for (int iy = std::max(0, int(std::floor(lo.y()))); iy <= std::min(ny_ - 1, int(std::floor(hi.y()))); ++iy) {
    for (int ix = std::max(0, int(std::floor(lo.x()))); ix <= std::min(nx_ - 1, int(std::floor(hi.x()))); ++ix) {
      const Cell& cell = cells_[static_cast<std::size_t>(cell_index(ix, iy))];
      out.insert(out.end(), cell.walls.begin(), cell.walls.end());
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  out.erase(std::remove_if(out.begin(), out.end(),
                           [&](int w) {
                             const Wall& wall = walls_[static_cast<std::size_t>(w)];
                             return (p - wall.a_N_m).dot(wall.normal_N) <= 1e-3 ||
                                    distance_to_segment(p, wall.a_N_m, wall.b_N_m) > max_distance_m;
                           }),
            out.end());
  return out;
}

std::optional<WallReflection> City::wall_reflection(const Eigen::Vector3d& p_N, const Eigen::Vector3d& u_N,
                                                    const std::vector<int>& candidate_walls) const {
  std::vector<WallReflection> found;
  for (const int w : candidate_walls) {
    const Wall& wall = walls_[static_cast<std::size_t>(w)];
    const Eigen::Vector3d n(wall.normal_N.x(), wall.normal_N.y(), 0.0);
    const double u_n = u_N.dot(n);
    if (u_n <= 1e-6) continue;  // satellite behind the wall
    const double d_m = (p_N.head<2>() - wall.a_N_m).dot(wall.normal_N);
    if (d_m <= 0.0) continue;
    const Eigen::Vector3d point = p_N - 2.0 * d_m * n + (d_m / u_n) * u_N;
    const Eigen::Vector2d e = wall.b_N_m - wall.a_N_m;
    const double t = (point.head<2>() - wall.a_N_m).dot(e) / e.squaredNorm();
    if (t < 0.0 || t > 1.0 || point.z() <= 0.0 || point.z() >= wall.height_m) continue;
    found.push_back({w, point, 2.0 * d_m * u_n});
  }
  std::sort(found.begin(), found.end(),
            [](const WallReflection& a, const WallReflection& b) { return a.excess_m < b.excess_m; });
  for (const WallReflection& r : found) {
    const int building = walls_[static_cast<std::size_t>(r.wall)].building;
    if (!segment_blocked(r.point_N_m, p_N, building) && !ray_blocked(r.point_N_m, u_N, building)) return r;
  }
  return std::nullopt;
}

bool City::inside_building(const Eigen::Vector2d& p_N) const {
  for (const Building& b : buildings_) {
    if (point_in_polygon(p_N, b.footprint_N_m)) return true;
  }
  return false;
}

City generate_city(const CityOptions& city, const TreeOptions& trees, const CityExtent& extent, std::uint64_t seed) {
  const StreetGrid grid = StreetGrid::from(city);
  Rng rng = Rng::stream(seed, kCityStream);
  const int i0 = static_cast<int>(std::lround(extent.min_G.x() / grid.pitch_x_m));
  const int i1 = static_cast<int>(std::lround(extent.max_G.x() / grid.pitch_x_m));
  const int j0 = static_cast<int>(std::lround(extent.min_G.y() / grid.pitch_y_m));
  const int j1 = static_cast<int>(std::lround(extent.max_G.y() / grid.pitch_y_m));
  const double half_w = grid.street_width_m / 2.0;
  std::vector<Building> buildings;
  const auto add_rect = [&](double x_lo, double y_lo, double x_hi, double y_hi, double height_m) {
    Building b;
    b.height_m = height_m;
    for (const Eigen::Vector2d& c : {Eigen::Vector2d(x_lo, y_lo), Eigen::Vector2d(x_hi, y_lo),
                                     Eigen::Vector2d(x_hi, y_hi), Eigen::Vector2d(x_lo, y_hi)}) {
      b.footprint_N_m.push_back(grid.to_N(c));
    }
    buildings.push_back(std::move(b));
  };
  // A lot overlapping the open square at the origin stays empty (its random draws are made all the same, so that the
  // rest of the city does not change with the square).
  const double square_half_m = city.start_square_m / 2.0;
  const auto in_start_square = [square_half_m](double x_lo, double y_lo, double x_hi, double y_hi) {
    return square_half_m > 0.0 && x_lo < square_half_m && x_hi > -square_half_m && y_lo < square_half_m &&
           y_hi > -square_half_m;
  };
  if (city.buildings) {
    for (int j = j0; j < j1; ++j) {
      for (int i = i0; i < i1; ++i) {
        const double x_lo = i * grid.pitch_x_m + half_w, x_hi = (i + 1) * grid.pitch_x_m - half_w;
        const double y_lo = j * grid.pitch_y_m + half_w, y_hi = (j + 1) * grid.pitch_y_m - half_w;
        const double y_mid = 0.5 * (y_lo + y_hi);
        for (const auto& [row_lo, row_hi] : {std::make_pair(y_lo, y_mid), std::make_pair(y_mid, y_hi)}) {
          for (double x = x_lo; x < x_hi - 1e-6;) {
            double width = rng.uniform(city.lot_width_min_m, city.lot_width_max_m);
            if (x_hi - (x + width) < city.lot_width_min_m) width = x_hi - x;
            const bool gap = rng.bernoulli(city.gap_probability);
            const double height =
                std::clamp(rng.normal(city.height_mean_m, city.height_sigma_m), city.height_min_m, city.height_max_m);
            if (!gap && height > 0.0 && !in_start_square(x, row_lo, x + width, row_hi)) {
              add_rect(x, row_lo, x + width, row_hi, height);
            }
            x += width;
          }
        }
      }
    }
  }
  std::vector<Tree> tree_list;
  if (trees.spacing_m > 0.0) {
    const double offset = half_w - trees.facade_offset_m;  // from the street centreline
    const auto plant = [&](const Eigen::Vector2d& p_G) {
      if (!rng.bernoulli(trees.presence_probability)) return;
      tree_list.push_back({grid.to_N(p_G), trees.crown_radius_m, trees.crown_bottom_m, trees.crown_top_m});
    };
    // Along the avenues (streets at y = j pitch_y), both sides, block frontage only.
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i < i1; ++i) {
        const double x0 = i * grid.pitch_x_m + half_w + trees.spacing_m / 2.0;
        for (int k = 0; x0 + k * trees.spacing_m < (i + 1) * grid.pitch_x_m - half_w; ++k) {
          plant({x0 + k * trees.spacing_m, j * grid.pitch_y_m - offset});
          plant({x0 + k * trees.spacing_m, j * grid.pitch_y_m + offset});
        }
      }
    }
    // Along the cross streets (x = i pitch_x).
    for (int i = i0; i <= i1; ++i) {
      for (int j = j0; j < j1; ++j) {
        const double y0 = j * grid.pitch_y_m + half_w + trees.spacing_m / 2.0;
        for (int k = 0; y0 + k * trees.spacing_m < (j + 1) * grid.pitch_y_m - half_w; ++k) {
          plant({i * grid.pitch_x_m - offset, y0 + k * trees.spacing_m});
          plant({i * grid.pitch_x_m + offset, y0 + k * trees.spacing_m});
        }
      }
    }
  }
  return City(grid, extent, std::move(buildings), std::move(tree_list));
}

}  // namespace canyon::sim
