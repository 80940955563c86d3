#pragma once
// The part of an RTK epoch that does not depend on the filter: both receivers' observables, the rover's satellite
// states and single-point solution, and the base's zero-difference models (the base does not move). RtkEngine's
// prediction builds it itself, or takes it built ahead, e.g. on the staged pipeline's time-bridge thread
// (pipeline/epoch_pipeline.hpp), where it runs beside the filter's work on the epoch before.
//
// Each single-point solution starts from the one before it, a chain that the filter never touches: a builder fed
// the same epochs in the same order gives the same geometry wherever it runs. The same holds for the cycle-slip
// detectors of the two receivers (rtk/cycle_slip.hpp), which depend on the observations alone: the builder owns them
// and scans each epoch that the engine goes on to use, so that the filter's thread does not spend its time on them.

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/geodesy.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/satellite.hpp"
#include "canyon/gnss/ephemeris.hpp"
#include "canyon/gnss/satellite_states.hpp"
#include "canyon/gnss/spp.hpp"
#include "canyon/rtk/cycle_slip.hpp"
#include "canyon/rtk/observables.hpp"

namespace canyon::rtk {

/// A base epoch tagged up to this much after the rover's still counts as simultaneous (s).
inline constexpr double kMaxBaseTimeAheadS = 0.05;

/// True if a base epoch `age_s` older than the rover's is not used: older than `max_age_s`, or ahead of it by more
/// than kMaxBaseTimeAheadS (the rule of RtkEngine::predict() and of the builder's slip scan).
[[nodiscard]] inline bool base_out_of_time(double age_s, double max_age_s) {
  return age_s > max_age_s || age_s < -kMaxBaseTimeAheadS;
}

/// The cycle-slip scan of one epoch: both receivers' detectors fed with its observables.
struct SlipScan {
  std::vector<SlipEvent> events;  ///< the rover's, then the base's (the base is fed only when its epoch is new)
  /// (satellite, frequency) pairs of the rover's signals whose latest phase at either receiver carries LLI bit 1
  /// (half cycle unresolved), sorted.
  std::vector<CycleSlipDetector::Key> half_cycle_unresolved;

  [[nodiscard]] bool half_cycle(core::SatelliteId sat, int frequency) const;
};

/// Zero-difference model of one satellite seen from one receiver.
struct ZeroDiff {
  bool valid = false;
  double model_m = 0.0;                             ///< rho (Sagnac) - c dts + troposphere
  Eigen::Vector3d los_E = Eigen::Vector3d::Zero();  ///< unit vector receiver -> satellite
  double elevation_rad = 0.0;
};

/// A receiver's position with its geodetic coordinates and ENU rotation, for the zero differences of an epoch.
struct ReceiverGeometry {
  Eigen::Vector3d p_E_m;
  core::Geodetic g;
  Eigen::Matrix3d R_NE;

  explicit ReceiverGeometry(const Eigen::Vector3d& p_E)
      : p_E_m(p_E), g(core::ecef_to_geodetic(p_E)), R_NE(core::rotation_enu_from_ecef(g)) {}
};

/// The zero difference of `sat` seen from `receiver`, its state at the transmission time given by `pseudorange_m`
/// (from `states`); invalid without a usable ephemeris.
[[nodiscard]] ZeroDiff zero_difference(gnss::EpochSatelliteStates& states, core::SatelliteId sat, double pseudorange_m,
                                       const ReceiverGeometry& receiver, bool troposphere);

/// Pseudorange of a satellite for the transmission-time computation: the first frequency that has one (NaN if none).
[[nodiscard]] double any_pseudorange(const ReceiverObservables& obs, core::SatelliteId sat);

/// One epoch's filter-independent inputs (see the top of this file).
struct EpochGeometry {
  gnss::EpochSatelliteStates rover_states;  ///< shared by the single-point solution and the rover zero differences
  Result<gnss::SppSolution> spp;
  ReceiverObservables rover_obs;
  bool has_base = false;
  ReceiverObservables base_obs;  ///< empty without a base epoch
  /// Zero differences of the base's satellites that have a pseudorange, in base_obs order (ascending satellite).
  std::vector<std::pair<core::SatelliteId, ZeroDiff>> base_models;
  /// The cycle-slip scan, present when the prediction goes on to the single differences: a base epoch within the
  /// age limits, and a single-point solution or aiding.
  std::optional<SlipScan> slips;

  /// The base model of `sat`; an invalid one if the base has none.
  [[nodiscard]] ZeroDiff base_model(core::SatelliteId sat) const;
};

/// Builds the geometry of epochs given in time order (one builder per stream of epochs; not thread-safe, but it may
/// live on another thread than the engine).
class EpochGeometryBuilder {
 public:
  struct Options {
    gnss::SppOptions spp;
    ObservableOptions observables;
    bool troposphere_saastamoinen = true;  ///< in the zero differences
    CycleSlipOptions slips;                ///< each receiver's cycle-slip detector
    double max_base_age_s = 30.0;          ///< base epochs older than this are not used (no slip scan)
  };
  EpochGeometryBuilder(Options options, const gnss::EphemerisStore& ephemerides, const Eigen::Vector3d& p_E_base_m);

  [[nodiscard]] const Options& options() const { return options_; }
  [[nodiscard]] const gnss::EphemerisStore& ephemerides() const { return *eph_; }
  /// A new base position (RTCM 1005/1006 that arrived on a stream) for the epochs built from now on.
  void set_base_position(const Eigen::Vector3d& p_E_base_m) {
    base_ = ReceiverGeometry(p_E_base_m);
    base_cache_.reset();
  }
  /// The geometry of `rover` (and `base`, nullptr if none); continues the single-point chain when it solves, and
  /// the slip detectors when the prediction goes on (EpochGeometry::slips). `aided`: the prediction is aided.
  [[nodiscard]] EpochGeometry build(const core::ObsEpoch& rover, const core::ObsEpoch* base, bool aided = false);

 private:
  Options options_;
  const gnss::EphemerisStore* eph_;
  ReceiverGeometry base_;
  std::optional<Eigen::Vector3d> last_spp_p_E_m_;
  CycleSlipDetector rover_slips_;
  CycleSlipDetector base_slips_;
  std::optional<core::GpsTime> last_base_time_;  // of the last base epoch fed to base_slips_
  // The base side of the last epoch built: a base epoch serves several rover epochs (a 1 Hz base and a 5 Hz rover),
  // and its observables and zero differences depend on it, the base position and the ephemerides alone.
  struct BaseSide {
    core::GpsTime time;
    std::size_t num_satellites;
    std::uint64_t ephemeris_stamp;  // gnss::EphemerisStore::selection_stamp()
    ReceiverObservables obs;
    std::vector<std::pair<core::SatelliteId, ZeroDiff>> models;
  };
  std::optional<BaseSide> base_cache_;

  /// The base side of `base`: from base_cache_ if it is that epoch's, else computed (and cached).
  [[nodiscard]] const BaseSide& base_side(const core::ObsEpoch& base);

  [[nodiscard]] SlipScan scan_slips(const EpochGeometry& geometry);
};

}  // namespace canyon::rtk
