// Receiver channels and clock (see tracking.hpp).

#include "canyon/sim/tracking.hpp"

#include <cmath>

namespace canyon::sim {

ChannelOutput Channel::step(double t_s, const SignalPath& path, const ReceiverOptions& rx) {
  const double dt_s = started_ ? t_s - last_t_s_ : 0.0;
  const bool first_epoch = !started_;
  started_ = true;
  last_t_s_ = t_s;
  ChannelOutput out;
  if (locked_) {
    if (!path.receivable || path.cn0_dbhz < rx.track_threshold_dbhz) {
      locked_ = false;
      ++losses_;
      receivable_since_s_ = -1.0;
      return out;
    }
    // Slips while locked: random (rarer on strong signals) or on a change of the received path.
    const double rate_hz = rx.slip_rate_hz * std::pow(10.0, -(path.cn0_dbhz - rx.track_threshold_dbhz) / 10.0);
    bool slip = rng_.bernoulli(1.0 - std::exp(-rate_hz * dt_s));
    const bool path_changed = path.direct != last_direct_ || (!path.direct && path.wall != last_wall_);
    if (path_changed && rng_.bernoulli(rx.path_change_slip_probability)) slip = true;
    last_direct_ = path.direct;
    last_wall_ = path.wall;
    if (slip) {
      ++slips_;
      ambiguity_cyc_ = new_ambiguity();
      out.loss_of_lock = true;
    }
    out.output = true;
    out.ambiguity_cyc = ambiguity_cyc_;
    return out;
  }
  // Not locked: acquire once the signal has been strong enough for the reacquisition time (at once on the first
  // epoch: the receiver has been running before the scenario starts).
  if (!path.receivable || path.cn0_dbhz < rx.acquire_threshold_dbhz) {
    receivable_since_s_ = -1.0;
    return out;
  }
  if (receivable_since_s_ < 0.0) receivable_since_s_ = t_s;
  if (!first_epoch && t_s - receivable_since_s_ < rx.reacquisition_s - 1e-9) return out;
  locked_ = true;
  out.loss_of_lock = ever_locked_;
  ever_locked_ = true;
  last_direct_ = path.direct;
  last_wall_ = path.wall;
  ambiguity_cyc_ = new_ambiguity();
  out.output = true;
  out.ambiguity_cyc = ambiguity_cyc_;
  return out;
}

ReceiverClock::ReceiverClock(const ReceiverOptions& rx, Rng rng) : rng_(rng), noise_(rx.clock_drift_noise) {
  initial_offset_s_ = rng_.uniform(-rx.clock_offset_max_s, rx.clock_offset_max_s);
  initial_drift_sps_ = rng_.uniform(-rx.clock_drift_max_sps, rx.clock_drift_max_sps);
  offset_s_ = initial_offset_s_;
  drift_sps_ = initial_drift_sps_;
}

void ReceiverClock::advance(double t_s) {
  const double dt_s = t_s - t_s_;
  if (dt_s <= 0.0) return;
  const double drift_before = drift_sps_;
  drift_sps_ += noise_ * std::sqrt(dt_s) * rng_.normal();
  offset_s_ += 0.5 * (drift_before + drift_sps_) * dt_s;
  t_s_ = t_s;
}

}  // namespace canyon::sim
