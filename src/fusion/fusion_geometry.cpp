// The filter-independent part of a fusion epoch (see fusion_geometry.hpp).

#include "canyon/fusion/fusion_geometry.hpp"

#include <utility>

namespace canyon::fusion {

FusionGeometryBuilder::FusionGeometryBuilder(const rtk::EpochGeometryBuilder::Options& options,
                                             const Cn0ScreenOptions& cn0, const gnss::EphemerisStore& ephemerides,
                                             const Eigen::Vector3d& p_E_base_m)
    : rtk_(options, ephemerides, p_E_base_m), screen_(cn0) {}

FusionGeometry FusionGeometryBuilder::build(const core::ObsEpoch& rover, const core::ObsEpoch* base) {
  FusionGeometry out{rtk_.build(rover, base, /*aided=*/true), std::nullopt, 0};
  if (out.rtk.spp) p_E_approx_m_ = out.rtk.spp->p_E_m;
  if (!screen_.enabled() || !p_E_approx_m_) return out;
  core::ObsEpoch screened = rover;
  out.screened = screen_.apply(screened, out.rtk.rover_states, *p_E_approx_m_);
  if (out.screened > 0) {
    out.screened_rover_obs = rtk::select_observables(screened, rtk_.ephemerides(), rtk_.options().observables);
  }
  return out;
}

}  // namespace canyon::fusion
