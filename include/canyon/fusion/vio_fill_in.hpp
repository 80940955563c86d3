#pragma once
// The VIO fill-in (Algorithm 1, line 22): when the float fails validation (float_validation.hpp), the epoch's output
// is the prior p_E,i+1|i, P_i+1|i (vio_prediction.hpp) with status VIO fill-in (RTKLIB's Q 7, dead reckoning).

#include "canyon/core/solution.hpp"
#include "canyon/core/time.hpp"
#include "canyon/fusion/vio_prediction.hpp"
#include "canyon/rtk/engine.hpp"

namespace canyon::fusion {

/// The fill-in of an epoch whose RTK result is `rtk_epoch` (the RTK filter's own prior when its time update ran
/// with the VIO motion, else `prior`), at GPST `t`.
[[nodiscard]] core::Solution vio_fill_in(const rtk::RtkEpoch& rtk_epoch, const Prior& prior, const core::GpsTime& t);

}  // namespace canyon::fusion
