// The output covariance's floor (see output_floor.hpp).

#include "canyon/fusion/output_floor.hpp"

#include <cmath>

#include "canyon/core/geodesy.hpp"

namespace canyon::fusion {

std::string OutputFloorOptions::validate() const {
  if (!(horizontal_sigma_m >= 0.0 && std::isfinite(horizontal_sigma_m)) ||
      !(vertical_sigma_m >= 0.0 && std::isfinite(vertical_sigma_m))) {
    return "output_sigma_floor_h_m and output_sigma_floor_v_m must be finite and >= 0";
  }
  if (!(unfixed_sigma_factor >= 1.0 && std::isfinite(unfixed_sigma_factor))) {
    return "output_unfixed_sigma_factor must be finite and >= 1";
  }
  return {};
}

void add_output_floor(core::Solution& solution, const OutputFloorOptions& options) {
  if (solution.status == core::SolutionStatus::None) return;
  if (solution.status != core::SolutionStatus::Fixed) {
    solution.P_E_m2 *= options.unfixed_sigma_factor * options.unfixed_sigma_factor;
  }
  if (options.horizontal_sigma_m == 0.0 && options.vertical_sigma_m == 0.0) return;
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(core::ecef_to_geodetic(solution.p_E_m));
  const double h2 = options.horizontal_sigma_m * options.horizontal_sigma_m;
  const Eigen::Vector3d floor_N(h2, h2, options.vertical_sigma_m * options.vertical_sigma_m);
  solution.P_E_m2 += R_NE.transpose() * floor_N.asDiagonal() * R_NE;
}

}  // namespace canyon::fusion
