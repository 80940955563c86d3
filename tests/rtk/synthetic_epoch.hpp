#pragma once
// A synthetic single-frequency GPS epoch for the RTK filter's unit tests: satellites at known lines of sight, true
// single-differenced integer ambiguities, and single differences formed at a prior that is `offset_E_m` off the true
// position (SD residual = -los . offset + lambda N, as single_difference.hpp forms them at the prior), with a filter
// state holding the position and one ambiguity per satellite.

#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "canyon/rtk/filter_state.hpp"
#include "canyon/rtk/single_difference.hpp"

namespace canyon::rtk::testing {

inline constexpr double kWavelengthM = 0.19029367279836487;

struct SyntheticEpoch {
  std::vector<SingleDiff> sds;
  std::vector<int> integers;  ///< true SD ambiguity of each satellite (cycles)
  FilterState state;
};

/// `count` satellites (PRN 1..count), elevations falling from 80 degrees, azimuths spread; the state's position at
/// the prior (zero) with variance `position_var_m2`, ambiguities at `ambiguity_value(i)` with `ambiguity_var_cyc2`.
template <typename AmbiguityValue>
SyntheticEpoch synthetic_epoch(int count, const Eigen::Vector3d& offset_E_m, double position_var_m2,
                               double ambiguity_var_cyc2, AmbiguityValue ambiguity_value) {
  SyntheticEpoch e;
  std::vector<FilterState::NewState> states;
  for (int i = 0; i < count; ++i) {
    const double el = (80.0 - 55.0 * i / std::max(count - 1, 1)) * 0.017453292519943295;
    const double az = 2.4 * i;
    SingleDiff sd;
    sd.sat = core::SatelliteId{core::Constellation::Gps, static_cast<std::uint8_t>(i + 1)};
    sd.frequency = 0;
    sd.group = 0;
    sd.wavelength_m = kWavelengthM;
    sd.los_E = Eigen::Vector3d(std::cos(el) * std::sin(az), std::cos(el) * std::cos(az), std::sin(el));
    sd.elevation_rad = el;
    const int integer = 7 * i - 20;
    e.integers.push_back(integer);
    const double range_m = -sd.los_E.dot(offset_E_m);
    sd.phase_m = range_m + kWavelengthM * integer;
    sd.code_m = range_m;
    sd.phase_variance_m2 = 2e-5;
    sd.code_variance_m2 = 0.2;
    sd.test_variance_m2 = 2e-5;
    sd.fixable = true;
    e.sds.push_back(sd);
    states.push_back({StateKey{sd.sat, 0}, ambiguity_value(i, integer), ambiguity_var_cyc2});
  }
  e.state.add(states);
  Eigen::MatrixXd P = e.state.P();
  P.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * position_var_m2;
  e.state.restore_values(e.state.x(), P);
  for (SingleDiff& sd : e.sds) sd.ambiguity = e.state.index({sd.sat, 0});
  return e;
}

}  // namespace canyon::rtk::testing
