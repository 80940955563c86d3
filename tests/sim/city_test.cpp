// City geometry: line of sight, specular wall reflections and foliage on hand-built cities with known answers.

#include "canyon/sim/city.hpp"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"

namespace canyon::sim {
namespace {

constexpr double kTolM = 1e-9;

/// Unit direction at azimuth (clockwise from north) and elevation, in ENU.
Eigen::Vector3d direction(double az_deg, double el_deg) {
  const double az = az_deg * core::kDegToRad, el = el_deg * core::kDegToRad;
  return {std::cos(el) * std::sin(az), std::cos(el) * std::cos(az), std::sin(el)};
}

Building box(double x0, double y0, double x1, double y1, double height_m) {
  return {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, height_m};
}

/// One 40 m high building east of the antenna: its west wall at x = 10 m, from y = -50 to 50.
City one_building() {
  CityExtent extent{{-200.0, -200.0}, {200.0, 200.0}};
  return City(StreetGrid{}, extent, {box(10.0, -50.0, 30.0, 50.0, 40.0)}, {});
}

TEST(CityTest, LineOfSightOverAndPastAWall) {
  const City city = one_building();
  const Eigen::Vector3d p(0.0, 0.0, 1.7);
  // East at 70 deg: the ray is at 1.7 + 10 tan(70) = 29.2 m at the wall: blocked. At 76 deg: 41.8 m: clear.
  EXPECT_TRUE(city.direct_blocked(p, direction(90.0, 70.0)));
  EXPECT_FALSE(city.direct_blocked(p, direction(90.0, 76.0)));
  EXPECT_FALSE(city.direct_blocked(p, direction(270.0, 10.0)));  // west: nothing
  EXPECT_FALSE(city.direct_blocked(p, direction(0.0, 5.0)));     // north along the wall
  // Azimuth 70 deg meets the wall at y = 3.6 m, 5.6 m up: blocked. Azimuth 5 deg passes north of the building (it
  // is at x = 4.4 m when it reaches y = 50 m).
  EXPECT_TRUE(city.direct_blocked(p, direction(70.0, 20.0)));
  EXPECT_FALSE(city.direct_blocked(p, direction(5.0, 20.0)));
}

TEST(CityTest, SpecularReflectionGeometry) {
  const City city = one_building();
  const Eigen::Vector3d p(0.0, 0.0, 1.7);
  const auto walls = city.walls_facing(p, 40.0);
  ASSERT_EQ(walls.size(), 1U);  // only the west wall faces the antenna
  // A satellite to the west-south-west (in front of the wall, whose outward normal points west).
  const Eigen::Vector3d u = direction(250.0, 30.0);
  const auto r = city.wall_reflection(p, u, walls);
  ASSERT_TRUE(r.has_value());
  const Eigen::Vector3d n(-1.0, 0.0, 0.0);
  EXPECT_NEAR(r->excess_m, 2.0 * 10.0 * u.dot(n), kTolM);
  EXPECT_NEAR(r->point_N_m.x(), 10.0, kTolM);
  // Brute force: the path satellite -> wall point -> antenna is longer than the direct one by the excess, and the
  // incoming and outgoing directions are mirror images across the wall.
  const Eigen::Vector3d to_antenna = (p - r->point_N_m).normalized();
  const Eigen::Vector3d mirrored_u(-u.x(), u.y(), u.z());
  EXPECT_NEAR((to_antenna - (-mirrored_u)).norm(), 0.0, 1e-9);
  const double direct = -u.dot(p);  // plane-wave path to p relative to the origin plane
  const double via_wall = -u.dot(r->point_N_m) + (p - r->point_N_m).norm();
  EXPECT_NEAR(via_wall - direct, r->excess_m, 1e-9);
  // A satellite behind the wall (east) has no reflection; one so low that the point would be on the ground neither.
  EXPECT_FALSE(city.wall_reflection(p, direction(90.0, 30.0), walls).has_value());
  EXPECT_FALSE(city.wall_reflection(p, direction(270.0, -10.0), walls).has_value());
}

TEST(CityTest, ReflectionNeedsAFreePath) {
  // A second, taller building west of the antenna hides the satellite from the wall's reflection point.
  CityExtent extent{{-200.0, -200.0}, {200.0, 200.0}};
  const City city(StreetGrid{}, extent, {box(10.0, -50.0, 30.0, 50.0, 40.0), box(-60.0, -50.0, -20.0, 50.0, 80.0)}, {});
  const Eigen::Vector3d p(0.0, 0.0, 1.7);
  const auto walls = city.walls_facing(p, 40.0);
  EXPECT_EQ(walls.size(), 2U);
  // West at 20 deg: the direct path is blocked by the west building; the reflection off the east building's west
  // wall (at x = 10) would come from the west too and cross the west building (80 m high) on its way: no path.
  const Eigen::Vector3d u = direction(270.0, 20.0);
  EXPECT_TRUE(city.direct_blocked(p, u));
  const auto r = city.wall_reflection(p, u, walls);
  EXPECT_FALSE(r.has_value());
  // At 70 deg the reflection clears the west building (point at height 1.7 + 10 tan 70 = 29 m, ray rises above 80 m
  // before x = -20).
  EXPECT_TRUE(city.wall_reflection(p, direction(270.0, 70.0), walls).has_value());
}

TEST(CityTest, FoliageLengthThroughACrown) {
  CityExtent extent{{-100.0, -100.0}, {100.0, 100.0}};
  const City city(StreetGrid{}, extent, {}, {Tree{{20.0, 0.0}, 3.0, 3.0, 12.0}});
  const Eigen::Vector3d p(0.0, 0.0, 1.7);
  // Horizontal distance 17..23 m east; at elevation el the ray is at 1.7 + s tan(el): for el = 15 deg it is 6.26 m
  // at 17 m and 7.86 m at 23 m, inside the crown all the way: length 6 / cos(15 deg).
  EXPECT_NEAR(city.foliage_m(p, direction(90.0, 15.0)), 6.0 / std::cos(15.0 * core::kDegToRad), 1e-9);
  // At 35 deg the ray leaves the crown top (12 m) at s = 10.3 / tan(35) = 14.7 m, before reaching it.
  EXPECT_NEAR(city.foliage_m(p, direction(90.0, 35.0)), 0.0, 1e-12);
  EXPECT_NEAR(city.foliage_m(p, direction(270.0, 15.0)), 0.0, 1e-12);
}

TEST(CityTest, GeneratedCityRespectsItsParameters) {
  CityOptions options;
  options.height_mean_m = 55.0;
  options.height_sigma_m = 15.0;
  options.height_min_m = 20.0;
  options.height_max_m = 81.0;
  options.grid_azimuth_deg = 30.0;
  const StreetGrid grid = StreetGrid::from(options);
  const CityExtent extent = blocks_extent({8, 8}, grid);
  const City city = generate_city(options, TreeOptions{}, extent, 5);
  ASSERT_GT(city.buildings().size(), 300U);
  double sum = 0.0, max = 0.0, min = 1e9;
  for (const Building& b : city.buildings()) {
    sum += b.height_m;
    max = std::max(max, b.height_m);
    min = std::min(min, b.height_m);
    for (const Eigen::Vector2d& c : b.footprint_N_m) EXPECT_TRUE(city.contains(c));
  }
  EXPECT_NEAR(sum / static_cast<double>(city.buildings().size()), 55.0, 2.0);
  EXPECT_EQ(max, 81.0);
  EXPECT_GE(min, 20.0);
  // Street centrelines and intersections are free; block centres are built up (unless the lot is a gap).
  for (int i = -3; i <= 3; ++i) {
    EXPECT_FALSE(city.inside_building(grid.to_N({i * grid.pitch_x_m, 17.0})));
    EXPECT_FALSE(city.inside_building(grid.to_N({13.0, i * grid.pitch_y_m})));
  }
}

// An open square at the origin, where a generated walk starts: no building overlaps it, and every other building is
// the one the city without the square has (the square does not reshuffle the city).
TEST(CityTest, StartSquareIsOpenAndTheRestOfTheCityUnchanged) {
  CityOptions options;
  options.grid_azimuth_deg = 30.0;
  const StreetGrid grid = StreetGrid::from(options);
  const CityExtent extent = blocks_extent({6, 6}, grid);
  const City closed = generate_city(options, TreeOptions{}, extent, 9);
  options.start_square_m = 120.0;
  const City open = generate_city(options, TreeOptions{}, extent, 9);
  ASSERT_LT(open.buildings().size(), closed.buildings().size());
  for (const Building& b : open.buildings()) {
    Eigen::Vector2d lo_G = grid.to_G(b.footprint_N_m.front()), hi_G = lo_G;
    for (const Eigen::Vector2d& c : b.footprint_N_m) {
      lo_G = lo_G.cwiseMin(grid.to_G(c));
      hi_G = hi_G.cwiseMax(grid.to_G(c));
    }
    const bool overlaps = lo_G.x() < 60.0 && hi_G.x() > -60.0 && lo_G.y() < 60.0 && hi_G.y() > -60.0;
    EXPECT_FALSE(overlaps) << "a building overlaps the start square at " << lo_G.transpose();
    const bool also_in_closed =
        std::any_of(closed.buildings().begin(), closed.buildings().end(), [&](const Building& c) {
          return c.height_m == b.height_m && (c.footprint_N_m.front() - b.footprint_N_m.front()).norm() < 1e-9;
        });
    EXPECT_TRUE(also_in_closed);
  }
  for (const double x : {-50.0, 0.0, 50.0}) {
    for (const double y : {-50.0, 0.0, 50.0}) EXPECT_FALSE(open.inside_building(grid.to_N({x, y})));
  }
}

}  // namespace
}  // namespace canyon::sim
