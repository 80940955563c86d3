#include "canyon/core/geodesy.hpp"

#include <random>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"

namespace canyon::core {
namespace {

constexpr double kMaxPositionErrorM = 1e-4;
constexpr double kMaxAngleErrorRad = 1e-11;

struct GeodeticCase {
  Geodetic geodetic;
  Eigen::Vector3d ecef;
};

// Table from independent sources: dataset READMEs (simulator inputs) and textbook points.
const GeodeticCase kCases[] = {
    {{48.780735783 * kDegToRad, 9.171992250 * kDegToRad, 320.0},
     {4157177.06580187, 671230.476590636, 4774767.03105544}},
    {{48.780735783 * kDegToRad, 9.199262450 * kDegToRad, 320.0}, {4156857.1195929, 673209.028774142, 4774767.03105544}},
    {{0.0, 0.0, 0.0}, {kWgs84SemiMajorM, 0.0, 0.0}},
    {{0.0, kPi / 2.0, 100.0}, {0.0, kWgs84SemiMajorM + 100.0, 0.0}},
    {{kPi / 2.0, 0.0, 0.0}, {0.0, 0.0, 6356752.314245179}},
    {{-kPi / 2.0, 0.0, -10.0}, {0.0, 0.0, -6356742.314245179}},
};

TEST(GeodesyTest, TableBothWays) {
  for (const auto& c : kCases) {
    const Eigen::Vector3d p = geodetic_to_ecef(c.geodetic);
    EXPECT_LT((p - c.ecef).norm(), 2e-3) << p.transpose();
    const Geodetic g = ecef_to_geodetic(c.ecef);
    EXPECT_NEAR(g.lat_rad, c.geodetic.lat_rad, 1e-9);
    if (std::abs(c.geodetic.lat_rad) < kPi / 2.0 - 1e-9) {
      EXPECT_NEAR(g.lon_rad, c.geodetic.lon_rad, 1e-9);
    }
    EXPECT_NEAR(g.height_m, c.geodetic.height_m, 2e-3);
  }
}

TEST(GeodesyTest, RandomRoundTripsFromGroundToGeo) {
  std::mt19937_64 rng(1234);
  std::uniform_real_distribution<double> lat(-kPi / 2.0, kPi / 2.0);
  std::uniform_real_distribution<double> lon(-kPi, kPi);
  std::uniform_real_distribution<double> height(-1000.0, 36.0e6);
  for (int i = 0; i < 20000; ++i) {
    const Geodetic g{lat(rng), lon(rng), height(rng)};
    const Eigen::Vector3d p = geodetic_to_ecef(g);
    const Geodetic back = ecef_to_geodetic(p);
    EXPECT_LT((geodetic_to_ecef(back) - p).norm(), kMaxPositionErrorM);
    EXPECT_NEAR(back.lat_rad, g.lat_rad, 1e-9);
    EXPECT_NEAR(back.height_m, g.height_m, kMaxPositionErrorM);
  }
}

TEST(GeodesyTest, EnuRotationIsOrthonormalAndRoundTrips) {
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> lat(-1.5, 1.5);
  std::uniform_real_distribution<double> lon(-kPi, kPi);
  std::uniform_real_distribution<double> d(-1e4, 1e4);
  for (int i = 0; i < 1000; ++i) {
    const Geodetic o{lat(rng), lon(rng), 0.0};
    const Eigen::Matrix3d R_NE = rotation_enu_from_ecef(o);
    EXPECT_LT((R_NE * R_NE.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(R_NE.determinant(), 1.0, 1e-12);
    const Eigen::Vector3d v(d(rng), d(rng), d(rng));
    EXPECT_LT((enu_to_ecef(ecef_to_enu(v, o), o) - v).norm(), 1e-8);
  }
  // Up is the ellipsoid normal: a point 100 m above is (0, 0, 100) in ENU.
  const Geodetic o{0.6, 2.4, 50.0};
  const Eigen::Vector3d up = ecef_to_enu(geodetic_to_ecef({0.6, 2.4, 150.0}) - geodetic_to_ecef(o), o);
  EXPECT_LT((up - Eigen::Vector3d(0, 0, 100.0)).norm(), 1e-6);
}

TEST(GeodesyTest, AzimuthElevationTable) {
  const Geodetic rcv{0.7, 0.3, 10.0};
  const Eigen::Vector3d p = geodetic_to_ecef(rcv);
  struct Case {
    Eigen::Vector3d enu;
    double az_deg, el_deg;
  };
  const Case cases[] = {{{0, 1e7, 0}, 0.0, 0.0},    {{1e7, 0, 0}, 90.0, 0.0},   {{0, -1e7, 0}, 180.0, 0.0},
                        {{-1e7, 0, 0}, 270.0, 0.0}, {{0, 1e7, 1e7}, 0.0, 45.0}, {{1e7, 0, -1e7}, 90.0, -45.0}};
  for (const auto& c : cases) {
    const AzEl ae = azimuth_elevation(p, rcv, p + enu_to_ecef(c.enu, rcv));
    EXPECT_NEAR(ae.azimuth_rad * kRadToDeg, c.az_deg, 1e-9);
    EXPECT_NEAR(ae.elevation_rad * kRadToDeg, c.el_deg, 1e-9);
  }
  // No receiver position yet: everything is overhead.
  EXPECT_NEAR(
      azimuth_elevation(Eigen::Vector3d::Zero(), ecef_to_geodetic(Eigen::Vector3d::Zero()), Eigen::Vector3d(2e7, 0, 0))
          .elevation_rad,
      kPi / 2.0, kMaxAngleErrorRad);
}

TEST(GeodesyTest, ElevationAloneIsTheElevationOfAzimuthElevation) {
  // Bit for bit: the engine and the SPP use the elevation-only forms where the azimuth is not needed.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    const Geodetic rcv{1.5 * unit(rng), 3.1 * unit(rng), 500.0 * unit(rng)};
    const Eigen::Vector3d p = geodetic_to_ecef(rcv);
    const Eigen::Vector3d sat = 2.6e7 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    const Eigen::Matrix3d R_NE = rotation_enu_from_ecef(rcv);
    EXPECT_EQ(elevation_rad(p, rcv, R_NE, sat), azimuth_elevation(p, rcv, sat).elevation_rad);
    EXPECT_EQ(elevation_from_enu(R_NE * (sat - p)), azimuth_elevation_from_enu(R_NE * (sat - p)).elevation_rad);
  }
  const Geodetic centre = ecef_to_geodetic(Eigen::Vector3d::Zero());
  EXPECT_EQ(elevation_rad(Eigen::Vector3d::Zero(), centre, rotation_enu_from_ecef(centre), Eigen::Vector3d(2e7, 0, 0)),
            kPi / 2.0);
}

}  // namespace
}  // namespace canyon::core
