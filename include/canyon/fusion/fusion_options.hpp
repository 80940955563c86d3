#pragma once
// Options of the fusion (fusion_engine.hpp), one struct per piece: the paper's (time bridge, VIO track, alignment,
// prediction, gates, float validation) and each addition beyond the paper (C/N0 screen, coarse alignment, heading
// state, integrity check, heading-free fill-in, false-fix guard, prior recovery), each described in its own header.

#include <string>

#include "canyon/fusion/alignment_schedule.hpp"
#include "canyon/fusion/cn0_screen.hpp"
#include "canyon/fusion/coarse_alignment.hpp"
#include "canyon/fusion/false_fix_guard.hpp"
#include "canyon/fusion/float_validation.hpp"
#include "canyon/fusion/heading_free_fill_in.hpp"
#include "canyon/fusion/heading_state.hpp"
#include "canyon/fusion/innovation_gates.hpp"
#include "canyon/fusion/integrity_check.hpp"
#include "canyon/fusion/output_floor.hpp"
#include "canyon/fusion/prior_recovery.hpp"
#include "canyon/fusion/time_bridge.hpp"
#include "canyon/fusion/vio_prediction.hpp"
#include "canyon/fusion/vio_track.hpp"

namespace canyon::fusion {

struct FusionOptions {
  // The paper's method.
  bool vio_on_gps_time = false;        ///< vio.csv t_ns is GPST ns since 1980-01-06 (no time-sync file needed)
  TimeBridgeOptions time_sync;         ///< the VIO clock to GPST (time_bridge.hpp)
  VioTrackOptions vio;                 ///< VIO segments, interpolation (vio_track.hpp)
  AlignmentScheduleOptions alignment;  ///< T_EO and t_IA, the paper's gates (alignment_schedule.hpp)
  PredictionOptions prediction;        ///< Eqs. 3-6 (vio_prediction.hpp)
  GateOptions gates;                   ///< outlier satellite pruning in the update (innovation_gates.hpp)
  FloatValidationOptions validation;   ///< (float_validation.hpp)
  // Beyond the paper, each in its own header.
  Cn0ScreenOptions cn0;
  CoarseAlignmentOptions coarse;
  HeadingStateOptions heading;
  IntegrityCheckOptions integrity;
  HeadingFreeFillInOptions heading_free;
  FalseFixGuardOptions guard;
  PriorRecoveryOptions recovery;
  OutputFloorOptions output_floor;
  double vio_keep_s = 120.0;  ///< VIO samples older than this before the epoch are forgotten (s; memory)

  /// Empty if valid, else the violated rule.
  [[nodiscard]] std::string validate() const;
};

}  // namespace canyon::fusion
