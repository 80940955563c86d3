#pragma once
// The messages between the stages of the estimation pipeline (epoch_pipeline.hpp), one type per stage boundary:
//
//   ingest ──IngestedEpoch──▶ time bridge ──BridgedEpoch──▶ alignment ──AlignedEpoch──▶ prediction ──PredictedEpoch──▶
//   update ──UpdatedEpoch──▶ ambiguity resolution ──SolvedEpoch──▶ sink
//
// Each message holds the one before it (moved, not copied: the epoch's observations and geometry stay where ingest
// and the time bridge allocated them) and adds what its stage produced, so a stage can only read what the stages
// before it made. The estimator's state (the RTK filter, the alignment) is not in the messages: it belongs to the
// estimator, which the four estimator stages use one epoch at a time.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/solution.hpp"
#include "canyon/fusion/fusion_geometry.hpp"
#include "canyon/fusion/vio_track.hpp"
#include "canyon/pipeline/link_counts.hpp"

namespace canyon::pipeline {

enum class Stage : std::uint8_t { Ingest, TimeBridge, Alignment, Prediction, Update, Ambiguity };
inline constexpr std::size_t kNumStages = 6;
/// "ingest", "time_bridge", "alignment", "prediction", "update", "ambiguity".
[[nodiscard]] const char* stage_name(Stage stage);

/// When an epoch entered and left each stage (the pipeline clock: monotonic ns).
struct StageClock {
  std::array<std::int64_t, kNumStages> enter_ns{};
  std::array<std::int64_t, kNumStages> exit_ns{};
};

/// Ingest's output: one rover epoch with its base epoch and what arrived with them.
struct IngestedEpoch {
  std::uint64_t seq = 0;  ///< 0, 1, 2, ... in ingest order
  core::ObsEpoch rover;
  std::optional<core::ObsEpoch> base;  ///< the base epoch to use (a copy: ingest runs ahead of the cursor's users)
  std::int64_t arrival_ns = 0;    ///< the epoch complete at ingest, rover and base (pipeline clock; 0: the pipeline
                                  ///< stamps it when the source returns it); the ingest stage is timed from it
  std::int64_t base_send_ns = 0;  ///< the base's send time of its epoch's last frame (DDS base; 0 otherwise)
  /// A base position that arrived on the base's stream (RTCM 1005/1006) and holds from this epoch on; set by ingest
  /// on the first epoch that has it and whenever it changes. The stages apply it with the epoch (the time bridge's
  /// geometry, the prediction's filter), so threaded and sequential runs use the same position for the same epoch.
  std::optional<Eigen::Vector3d> base_position_E_m;
  LinkCounts rover_link;  ///< the receiver's stream (ubx input), as ingest left it with this epoch
  LinkCounts base_link;   ///< the base's stream (dds, ntrip, tcp)
  /// Ephemerides that arrived on the rover's or the base's stream before this epoch (nullptr: none). The pipeline
  /// hands them to the estimator before the epoch's time bridge, once every earlier epoch has left the last stage: no
  /// stage reads the ephemerides meanwhile, and threaded and sequential runs use the same ephemerides for the same
  /// epoch.
  std::shared_ptr<const core::NavigationData> navigation;
  StageClock clock;  ///< stamped by the pipeline as the epoch passes each stage

  /// The base epoch to use, or nullptr.
  [[nodiscard]] const core::ObsEpoch* base_epoch() const { return base ? &*base : nullptr; }
};

/// The time bridge's output: the epoch's filter-independent geometry (rtk/epoch_geometry.hpp; with the C/N0 screen's
/// verdict in fusion) and, in fusion, the VIO pose at the epoch's GPST.
struct BridgedEpoch {
  IngestedEpoch epoch;
  fusion::FusionGeometry geometry;
  std::optional<fusion::VioPoseAt> pose;
};

/// The alignment's output: the estimator's alignment is up to date for the epoch (nothing of the epoch changes).
struct AlignedEpoch {
  BridgedEpoch bridged;
};

/// The prediction's verdict: the epoch goes on to the update (true), its result is final (false), or it has no
/// solution at all (the error).
struct PredictedEpoch {
  AlignedEpoch aligned;
  Result<bool> verdict = false;
};

/// The update's verdict: the epoch goes on to ambiguity resolution.
struct UpdatedEpoch {
  PredictedEpoch predicted;
  bool to_resolve = false;
};

/// The epoch's output (after the ambiguity stage).
struct EpochOutput {
  core::Solution solution;
  double hdop = 0.0;
  std::string note;  ///< why not fixed
  std::vector<core::SatelliteId> rejected;
  std::vector<core::SatelliteId> ar_pruned;
  bool aided = false;
  /// The update stage's float solution and the prediction's prior (aided epochs), from the RTK filter.
  bool has_float = false;
  Eigen::Vector3d float_p_E_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d float_P_E_m2 = Eigen::Matrix3d::Zero();
  int dd_phase_rows = 0;
  int dd_code_rows = 0;
  double max_post_fit_normalised = 0.0;
  bool has_prior = false;
  Eigen::Vector3d prior_p_E_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d prior_P_E_m2 = Eigen::Matrix3d::Zero();
  /// Fusion: the last accepted alignment (RMSE, first eigenvalue ratio) and the lever arm in use.
  struct Alignment {
    std::string kind;
    double rmse_m = 0.0;
    double first_eigenvalue_ratio = 0.0;
    Eigen::Vector3d t_IA_m = Eigen::Vector3d::Zero();
  };
  std::optional<Alignment> alignment;
};

/// The ambiguity stage's output, what the sink receives: the epoch and its output, or why it has none.
struct SolvedEpoch {
  UpdatedEpoch updated;
  Result<EpochOutput> output = Error{"not solved"};

  [[nodiscard]] const IngestedEpoch& epoch() const { return updated.predicted.aligned.bridged.epoch; }
  [[nodiscard]] IngestedEpoch& epoch() { return updated.predicted.aligned.bridged.epoch; }
  /// The time bridge's VIO pose (fusion), if any.
  [[nodiscard]] const std::optional<fusion::VioPoseAt>& pose() const { return updated.predicted.aligned.bridged.pose; }
};

// The epoch record of any stage message.
[[nodiscard]] inline IngestedEpoch& epoch_of(IngestedEpoch& m) {
  return m;
}
[[nodiscard]] inline IngestedEpoch& epoch_of(BridgedEpoch& m) {
  return m.epoch;
}
[[nodiscard]] inline IngestedEpoch& epoch_of(AlignedEpoch& m) {
  return m.bridged.epoch;
}
[[nodiscard]] inline IngestedEpoch& epoch_of(PredictedEpoch& m) {
  return m.aligned.bridged.epoch;
}
[[nodiscard]] inline IngestedEpoch& epoch_of(UpdatedEpoch& m) {
  return m.predicted.aligned.bridged.epoch;
}
[[nodiscard]] inline IngestedEpoch& epoch_of(SolvedEpoch& m) {
  return m.epoch();
}

}  // namespace canyon::pipeline
