#pragma once
// The constant-velocity prediction, an ablation of the paper's VIO prediction (prediction: constant_velocity; RTKLIB's
// kind of motion model, the paper's baseline): the increment is v dt from the last two fixed or float solutions (none
// if they are more than 5 s apart or imply more than max_speed_mps), with covariance
// (sigma_a^2 dt^3 / 3) I + (P_k + P_k-1) (dt / dt_k)^2, sigma_a the RTK option accel_sigma_h_mps2.

#include <optional>
#include <vector>

#include "canyon/core/solution.hpp"
#include "canyon/core/time.hpp"
#include "canyon/fusion/vio_prediction.hpp"

namespace canyon::fusion {

/// The motion from the state's epoch `t_state` to `t` (dp and Q; the prior is not filled), from the last two
/// solutions (oldest first); nullopt if there is none (see above).
[[nodiscard]] std::optional<MotionPrediction> predict_constant_velocity(const std::vector<core::Solution>& last_two,
                                                                        const core::GpsTime& t,
                                                                        const core::GpsTime& t_state,
                                                                        double max_speed_mps, double accel_sigma_mps2);

}  // namespace canyon::fusion
