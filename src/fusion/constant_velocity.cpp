// The constant-velocity ablation (see constant_velocity.hpp).

#include "canyon/fusion/constant_velocity.hpp"

namespace canyon::fusion {

std::optional<MotionPrediction> predict_constant_velocity(const std::vector<core::Solution>& last_two,
                                                          const core::GpsTime& t, const core::GpsTime& t_state,
                                                          double max_speed_mps, double accel_sigma_mps2) {
  if (last_two.size() < 2) return std::nullopt;
  const core::Solution& a = last_two[0];
  const core::Solution& b = last_two[1];
  const double dt_k = b.time - a.time;
  const double dt = t - t_state;
  if (!(dt_k > 0.0) || dt_k > 5.0 || dt < 0.0) return std::nullopt;
  const Eigen::Vector3d v = (b.p_E_m - a.p_E_m) / dt_k;
  if (!(v.norm() <= max_speed_mps)) return std::nullopt;  // a jump between solutions, not a motion
  MotionPrediction prediction;
  prediction.dp_E_m = v * dt;
  const double sa = accel_sigma_mps2;
  prediction.Q_E_m2 =
      Eigen::Matrix3d::Identity() * sa * sa * dt * dt * dt / 3.0 + (a.P_E_m2 + b.P_E_m2) * (dt / dt_k) * (dt / dt_k);
  return prediction;
}

}  // namespace canyon::fusion
