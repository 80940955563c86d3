#pragma once
// The city footprint for plots, read from GeoJSON as `canyon simulate` writes it (city.geojson, see
// src/sim/output.cpp): a FeatureCollection in WGS84 longitude/latitude (degrees) of
//   - Polygon features of kind "building" (or without a kind): footprint (first ring), property height_m;
//   - Point features of kind "tree" (radius_m, 3 m if absent), "origin" (the city's ENU origin; height_m, the ground's
//     ellipsoidal height) and "base";
//   - a LineString of kind "route".
// Other features are ignored. Errors name the file and line: JSON syntax, a root that is not a FeatureCollection,
// a feature without geometry, malformed or out-of-range coordinates, a polygon of fewer than three points.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/geodesy.hpp"
#include "canyon/core/result.hpp"

namespace canyon::eval {

struct CityMapBuilding {
  std::vector<Eigen::Vector2d> lon_lat_deg;  ///< footprint ring (longitude, latitude), not repeating the first point
  double height_m = 0.0;                     ///< above the ground
};

struct CityMapTree {
  Eigen::Vector2d lon_lat_deg = Eigen::Vector2d::Zero();
  double radius_m = 3.0;  ///< crown radius
};

struct CityMap {
  std::vector<CityMapBuilding> buildings;
  std::vector<CityMapTree> trees;
  std::vector<Eigen::Vector2d> route_lon_lat_deg;
  std::optional<core::Geodetic> origin;  ///< the "origin" point at its ground height, if the file has one
};

/// Reads a city GeoJSON file (see above).
Result<CityMap> read_city_geojson(const std::string& path);

}  // namespace canyon::eval
