// The pedestrian's path and trajectory (see route.hpp).

#include "canyon/sim/route.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "canyon/core/constants.hpp"
#include "canyon/sim/random.hpp"

namespace canyon::sim {
namespace {

constexpr double kMaxRoundedTurnRad = 150.0 * core::kDegToRad;
constexpr std::uint64_t kRouteStream = 0x20E7E;

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

Eigen::Vector2d left_of(const Eigen::Vector2d& d) {
  return {-d.y(), d.x()};
}

Eigen::Vector2d rotate(const Eigen::Vector2d& d, double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  return {c * d.x() - s * d.y(), s * d.x() + c * d.y()};
}

}  // namespace

Path Path::through(const std::vector<Eigen::Vector2d>& points_N, double turn_radius_m) {
  Path path;
  path.points_N_ = points_N;
  const std::size_t n = points_N.size();
  std::vector<Eigen::Vector2d> dirs;
  std::vector<double> lengths;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const Eigen::Vector2d e = points_N[k + 1] - points_N[k];
    lengths.push_back(e.norm());
    dirs.push_back(e.normalized());
  }
  // Corner k (at points_N[k + 1]) between segment k and k + 1: turn angle and the length cut from each side.
  std::vector<double> turn(n, 0.0), cut(n, 0.0), radius(n, 0.0);
  for (std::size_t k = 0; k + 1 < dirs.size(); ++k) {
    const double angle = std::atan2(cross(dirs[k], dirs[k + 1]), dirs[k].dot(dirs[k + 1]));
    if (std::abs(angle) < 1e-9 || std::abs(angle) > kMaxRoundedTurnRad || turn_radius_m <= 0.0) continue;
    const double t = std::tan(std::abs(angle) / 2.0);
    const double c = std::min({turn_radius_m * t, 0.5 * lengths[k], 0.5 * lengths[k + 1]});
    turn[k] = angle;
    cut[k] = c;
    radius[k] = c / t;
  }
  double s = 0.0;
  for (std::size_t k = 0; k < dirs.size(); ++k) {
    const double cut_in = k > 0 ? cut[k - 1] : 0.0;
    const double cut_out = cut[k];
    Piece line;
    line.s0_m = s;
    line.start_N = points_N[k] + cut_in * dirs[k];
    line.direction_N = dirs[k];
    line.length_m = std::max(0.0, lengths[k] - cut_in - cut_out);
    path.pieces_.push_back(line);
    s += line.length_m;
    if (k + 1 < dirs.size() && cut[k] > 0.0) {
      Piece arc;
      arc.s0_m = s;
      arc.start_N = points_N[k + 1] - cut_out * dirs[k];
      arc.direction_N = dirs[k];
      arc.curvature_1pm = (turn[k] > 0.0 ? 1.0 : -1.0) / radius[k];
      arc.length_m = radius[k] * std::abs(turn[k]);
      path.pieces_.push_back(arc);
      s += arc.length_m;
    }
  }
  path.length_m_ = s;
  return path;
}

const Path::Piece& Path::piece_at(double s_m) const {
  const auto it =
      std::upper_bound(pieces_.begin(), pieces_.end(), s_m, [](double s, const Piece& p) { return s < p.s0_m; });
  return it == pieces_.begin() ? pieces_.front() : *std::prev(it);
}

Eigen::Vector2d Path::position_N(double s_m) const {
  s_m = std::clamp(s_m, 0.0, length_m_);
  const Piece& p = piece_at(s_m);
  const double ds = s_m - p.s0_m;
  if (p.curvature_1pm == 0.0) return p.start_N + ds * p.direction_N;
  const double k = p.curvature_1pm;
  const double phi = k * ds;
  return p.start_N + (std::sin(phi) / k) * p.direction_N + ((1.0 - std::cos(phi)) / k) * left_of(p.direction_N);
}

Eigen::Vector2d Path::direction_N(double s_m) const {
  s_m = std::clamp(s_m, 0.0, length_m_);
  const Piece& p = piece_at(s_m);
  return rotate(p.direction_N, p.curvature_1pm * (s_m - p.s0_m));
}

std::vector<Eigen::Vector2d> random_walk_G(const RouteOptions& route, const StreetGrid& grid, double length_m,
                                           const CityExtent* extent, std::uint64_t seed) {
  Rng rng = Rng::stream(seed, kRouteStream);
  const Eigen::Vector2d pitch(grid.pitch_x_m, grid.pitch_y_m);
  // Intersections allowed: strictly inside the extent (the boundary streets have buildings on one side only).
  Eigen::Vector2i lo(-1000000, -1000000), hi(1000000, 1000000);
  if (extent != nullptr) {
    lo = Eigen::Vector2i(int(std::lround(extent->min_G.x() / pitch.x())) + 1,
                         int(std::lround(extent->min_G.y() / pitch.y())) + 1);
    hi = Eigen::Vector2i(int(std::lround(extent->max_G.x() / pitch.x())) - 1,
                         int(std::lround(extent->max_G.y() / pitch.y())) - 1);
  }
  const auto inside = [&](const Eigen::Vector2i& v) {
    return (v.array() >= lo.array()).all() && (v.array() <= hi.array()).all();
  };
  const std::array<Eigen::Vector2i, 4> headings = {Eigen::Vector2i(1, 0), Eigen::Vector2i(0, 1), Eigen::Vector2i(-1, 0),
                                                   Eigen::Vector2i(0, -1)};
  Eigen::Vector2i at(0, 0);
  if (!inside(at)) at = (lo + hi) / 2;
  int heading = static_cast<int>(rng.integer(0, 3));
  std::vector<Eigen::Vector2i> nodes = {at};
  std::vector<int> moves;
  double walked_m = 0.0;
  while (walked_m < length_m) {
    const int left = (heading + 1) % 4, right = (heading + 3) % 4, back = (heading + 2) % 4;
    const auto ok = [&](int h) { return inside(at + headings[static_cast<std::size_t>(h)]); };
    int next = heading;
    const bool want_turn = rng.bernoulli(route.turn_probability);
    const int first_turn = rng.bernoulli(0.5) ? left : right;
    const int other_turn = first_turn == left ? right : left;
    if (want_turn || !ok(heading)) {
      next = ok(first_turn) ? first_turn : ok(other_turn) ? other_turn : ok(heading) ? heading : back;
    }
    if (!ok(next)) break;  // a single intersection: nowhere to go
    heading = next;
    at += headings[static_cast<std::size_t>(heading)];
    nodes.push_back(at);
    moves.push_back(heading);
    walked_m += std::abs(headings[static_cast<std::size_t>(heading)].x()) * pitch.x() +
                std::abs(headings[static_cast<std::size_t>(heading)].y()) * pitch.y();
  }
  // The walking line: offset to the right of the street centreline by (street width / 2 - sidewalk offset).
  const double offset = grid.street_width_m / 2.0 - route.sidewalk_offset_m;
  const auto right_of = [&](int h) {
    const Eigen::Vector2d d = headings[static_cast<std::size_t>(h)].cast<double>();
    return Eigen::Vector2d(d.y(), -d.x());
  };
  const auto node = [&](std::size_t k) { return Eigen::Vector2d(nodes[k].cast<double>().cwiseProduct(pitch)); };
  std::vector<Eigen::Vector2d> points;
  if (moves.empty()) return {node(0), node(0) + Eigen::Vector2d(1.0, 0.0)};
  points.emplace_back(node(0) + offset * right_of(moves.front()));
  for (std::size_t k = 1; k < moves.size(); ++k) {
    if (moves[k] == moves[k - 1]) continue;
    if (moves[k] == (moves[k - 1] + 2) % 4) {  // turning back: cross the street
      points.emplace_back(node(k) + offset * right_of(moves[k - 1]));
      points.emplace_back(node(k) + offset * right_of(moves[k]));
    } else {
      points.emplace_back(node(k) + offset * (right_of(moves[k - 1]) + right_of(moves[k])));
    }
  }
  points.emplace_back(node(moves.size()) + offset * right_of(moves.back()));
  return points;
}

double Trajectory::arc_length(double t_s, double* direction_sign) const {
  const double walked_m = options_.speed_mps * std::max(0.0, t_s);
  const double length_m = path_.length_m();
  if (direction_sign != nullptr) *direction_sign = 1.0;
  if (length_m <= 0.0) return 0.0;
  if (walked_m <= length_m) return walked_m;
  // Back and forth.
  const double phase_m = std::fmod(walked_m, 2.0 * length_m);
  if (phase_m <= length_m) return phase_m;
  if (direction_sign != nullptr) *direction_sign = -1.0;
  return 2.0 * length_m - phase_m;
}

Eigen::Vector3d Trajectory::antenna_N(double t_s) const {
  const Eigen::Vector2d p = path_.position_N(arc_length(t_s));
  const double bob_m = options_.head_bob_m * std::sin(2.0 * core::kPi * options_.step_frequency_hz * t_s);
  return {p.x(), p.y(), options_.antenna_height_m + bob_m};
}

Eigen::Vector3d Trajectory::velocity_N(double t_s) const {
  double sign = 1.0;
  const double s = arc_length(t_s, &sign);
  const Eigen::Vector2d v = (options_.speed_mps * sign) * path_.direction_N(s);
  const double w = 2.0 * core::kPi * options_.step_frequency_hz;
  return {v.x(), v.y(), options_.head_bob_m * w * std::cos(w * t_s)};
}

Eigen::Vector2d Trajectory::heading_N(double t_s) const {
  double sign = 1.0;
  const double s = arc_length(t_s, &sign);
  return sign * path_.direction_N(s);
}

}  // namespace canyon::sim
