// The VIO fill-in, Algorithm 1 line 22 (see vio_fill_in.hpp).

#include "canyon/fusion/vio_fill_in.hpp"

namespace canyon::fusion {

core::Solution vio_fill_in(const rtk::RtkEpoch& rtk_epoch, const Prior& prior, const core::GpsTime& t) {
  core::Solution s = rtk_epoch.solution;
  if (s.status == core::SolutionStatus::None) s.time = t;
  s.status = core::SolutionStatus::VioFillIn;
  s.fixed_combinations = 0;
  s.p_E_m = rtk_epoch.aided ? rtk_epoch.prior_p_E_m : prior.p_E_m;
  s.P_E_m2 = rtk_epoch.aided ? rtk_epoch.prior_P_E_m2 : prior.P_E_m2;
  s.ratio = 0.0;
  return s;
}

}  // namespace canyon::fusion
