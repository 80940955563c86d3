#pragma once
// The filter-independent part of a fusion epoch: the RTK geometry of all the rover's signals (rtk/epoch_geometry.hpp:
// satellite states, single-point solution, observables, the base's zero differences, the cycle-slip scan) and the
// C/N0 screen's verdict on them (cn0_screen.hpp). FusionEngine's prediction builds it itself, or takes it built ahead,
// e.g. on the staged pipeline's time-bridge thread (pipeline/epoch_pipeline.hpp), beside the filter's work on the epoch
// before.
//
// Nothing here reads the filter: the single-point chain, the slip detectors and the screen's learning depend on the
// observations alone, so a builder fed the same epochs in the same order gives the same result wherever it runs.
// The screen learns from every epoch once a single-point position exists (its elevations are computed from the
// latest one: metres of error move an elevation by microradians) and gives its verdict on every epoch; the
// prediction applies it to aided epochs only (before the VIO is aligned the RTK engine needs every signal for the
// solutions the alignment starts from). The slip detectors see every signal, screened or not, and scan every epoch
// whose base epoch is within the age limits (a fusion epoch without a single point may still be aided).

#include <optional>

#include <Eigen/Core>

#include "canyon/core/observation.hpp"
#include "canyon/fusion/cn0_screen.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/rtk/epoch_geometry.hpp"
#include "canyon/rtk/observables.hpp"

namespace canyon::fusion {

struct FusionGeometry {
  rtk::EpochGeometry rtk;  ///< of all the rover's signals
  /// The rover's observables without the signals the C/N0 screen suspects of NLOS; set when it removed any.
  std::optional<rtk::ReceiverObservables> screened_rover_obs;
  int screened = 0;  ///< signals the screen removed
};

/// Builds the fusion geometry of epochs given in time order (one builder per stream of epochs; not thread-safe, but
/// it may live on another thread than the engine).
class FusionGeometryBuilder {
 public:
  FusionGeometryBuilder(const rtk::EpochGeometryBuilder::Options& options, const Cn0ScreenOptions& cn0,
                        const gnss::EphemerisStore& ephemerides, const Eigen::Vector3d& p_E_base_m);

  /// A new base position for the epochs built from now on.
  void set_base_position(const Eigen::Vector3d& p_E_base_m) { rtk_.set_base_position(p_E_base_m); }
  /// The geometry of `rover` (and `base`, nullptr if none) and the screen's verdict on it.
  [[nodiscard]] FusionGeometry build(const core::ObsEpoch& rover, const core::ObsEpoch* base);

 private:
  rtk::EpochGeometryBuilder rtk_;
  Cn0Screen screen_;
  std::optional<Eigen::Vector3d> p_E_approx_m_;  // the latest single-point position
};

}  // namespace canyon::fusion
