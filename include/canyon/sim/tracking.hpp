#pragma once
// Receiver tracking: one channel per (satellite, signal) with lock, ambiguity and loss-of-lock state, and the
// receiver clock.
//
// A channel is locked while its signal is receivable (a direct or reflected path, C/N0 at least the tracking
// threshold). When it is not, lock is lost; the signal is output again once it has been receivable with at least the
// acquisition threshold for `reacquisition_s`, with a new random integer ambiguity and the loss-of-lock bit (LLI
// bit 0) set on that first epoch, as a receiver sets it. While locked, the phase loop slips (new ambiguity, LLI set)
// at a rate that falls tenfold per 10 dB above the tracking threshold, and with `path_change_slip_probability` when
// the received path changes (direct <-> reflected, or another wall); otherwise the carrier phase follows the path
// length continuously -- a line-of-sight to NLOS transition then leaves no flag, as in a real receiver. Signals
// acquired for the first time (a rising satellite, the first epoch) carry no flag.
//
// Clock: offset and drift start uniformly in +-clock_offset_max_s and +-clock_drift_max_sps; the drift is a random
// walk (clock_drift_noise per sqrt(s)) and the offset its integral.

#include <cstdint>

#include "canyon/sim/random.hpp"
#include "canyon/sim/scenario.hpp"

namespace canyon::sim {

/// What a channel outputs at one epoch.
struct ChannelOutput {
  bool output = false;        ///< the signal is in the observation file at this epoch
  bool loss_of_lock = false;  ///< LLI bit 0 set
  std::int64_t ambiguity_cyc = 0;
};

/// The path a signal arrives by at one epoch.
struct SignalPath {
  bool receivable = false;  ///< some path exists (direct or reflected) above the elevation cutoff
  bool direct = false;      ///< direct path (otherwise a reflection)
  int wall = -1;            ///< reflecting wall of an NLOS signal
  double cn0_dbhz = 0.0;    ///< C/N0 of what arrives
};

class Channel {
 public:
  explicit Channel(Rng rng) : rng_(rng) {}
  /// Advances to an epoch at `t_s` (seconds since the start, increasing) with the path of this epoch.
  ChannelOutput step(double t_s, const SignalPath& path, const ReceiverOptions& rx);
  [[nodiscard]] bool locked() const { return locked_; }
  /// Counters for the run summary.
  [[nodiscard]] int losses() const { return losses_; }
  [[nodiscard]] int slips() const { return slips_; }
  /// The channel's own generator (noise of its observables).
  Rng& rng() { return rng_; }

 private:
  std::int64_t new_ambiguity() { return rng_.integer(-1000, 1000); }

  Rng rng_;
  bool locked_ = false;
  bool ever_locked_ = false;
  bool started_ = false;
  double receivable_since_s_ = -1.0;  ///< < 0: not receivable at the acquisition threshold
  double last_t_s_ = 0.0;
  bool last_direct_ = true;
  int last_wall_ = -1;
  std::int64_t ambiguity_cyc_ = 0;
  int losses_ = 0;
  int slips_ = 0;
};

class ReceiverClock {
 public:
  ReceiverClock(const ReceiverOptions& rx, Rng rng);
  /// Advances to `t_s` (seconds since the start, increasing).
  void advance(double t_s);
  [[nodiscard]] double offset_s() const { return offset_s_; }
  [[nodiscard]] double drift_sps() const { return drift_sps_; }
  [[nodiscard]] double initial_offset_s() const { return initial_offset_s_; }
  [[nodiscard]] double initial_drift_sps() const { return initial_drift_sps_; }

 private:
  Rng rng_;
  double noise_ = 0.0;
  double offset_s_ = 0.0;
  double drift_sps_ = 0.0;
  double initial_offset_s_ = 0.0;
  double initial_drift_sps_ = 0.0;
  double t_s_ = 0.0;
};

}  // namespace canyon::sim
