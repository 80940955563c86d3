#pragma once
// Beyond the paper: the covariance a solution is output with, floored. The filter's covariance holds the errors it
// models; a fix averaged over many epochs then claims millimetres while wall multipath (up to a centimetre on each
// carrier phase, slowly varying: not white) leaves centimetres. The output covariance is the filter's plus a floor in
// the local frame,
//   P_out = P + R_EN diag(h^2, h^2, v^2) R_NE,
// h and v the horizontal and vertical sigma of what the filter does not model (the "1 cm + 1 ppm" of a receiver's
// specification). Only the output: the filter, its fixes and the alignment keep their own covariance.

#include <string>

#include "canyon/core/solution.hpp"

namespace canyon::fusion {

struct OutputFloorOptions {
  double horizontal_sigma_m = 0.01;  ///< h (m); 0 with v = 0: no floor
  double vertical_sigma_m = 0.02;    ///< v (m)

  [[nodiscard]] std::string validate() const;
};

/// Adds the floor to a solution's covariance (not to one without a solution).
void add_output_floor(core::Solution& solution, const OutputFloorOptions& options);

}  // namespace canyon::fusion
