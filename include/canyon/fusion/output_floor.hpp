#pragma once
// Beyond the paper: the covariance a solution is output with, floored. The filter's covariance holds the errors it
// models; a fix averaged over many epochs then claims millimetres while wall multipath (up to a centimetre on each
// carrier phase, slowly varying: not white) leaves centimetres. The output covariance is the filter's plus a floor in
// the local frame,
//   P_out = P + R_EN diag(h^2, h^2, v^2) R_NE,
// h and v the horizontal and vertical sigma of what the filter does not model (the "1 cm + 1 ppm" of a receiver's
// specification). A solution that is not fixed (float, VIO fill-in, single point) has its filter covariance scaled
// first,
//   P_out = k^2 P + R_EN diag(h^2, h^2, v^2) R_NE,
// k = unfixed_sigma_factor: the filter takes code errors as white, and in a street canyon code multipath stays for
// tens of seconds, so a float (and the fill-in that carries it on) averages biased code and claims a precision it
// lacks (downtown development seeds 1-10: a float's median error is 2.45 of its sigma along the worse horizontal axis,
// a fill-in's 1.97, a fix's 0.40). A fix's integers pin the position on carrier phase, which that bias does not reach.
// Only the output: the filter, its fixes and the alignment keep their own covariance.

#include <string>

#include "canyon/core/solution.hpp"

namespace canyon::fusion {

struct OutputFloorOptions {
  double horizontal_sigma_m = 0.01;   ///< h (m); 0 with v = 0: no floor
  double vertical_sigma_m = 0.02;     ///< v (m)
  double unfixed_sigma_factor = 3.0;  ///< k (>= 1; 1: a solution not fixed keeps its filter covariance)

  [[nodiscard]] std::string validate() const;
};

/// Adds the floor to a solution's covariance (not to one without a solution).
void add_output_floor(core::Solution& solution, const OutputFloorOptions& options);

}  // namespace canyon::fusion
