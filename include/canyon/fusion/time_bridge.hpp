#pragma once
// Time bridge: maps the VIO device clock to GPST through the device's built-in GPS, which reports GPST at known
// device-clock instants (timesync.csv pairs).
//
// Model (one line, offset and drift):
//   t_gps(t_ns) - t_ref = a + b (t_ns - n_ref) 1e-9 s,
// with (n_ref, t_ref) the first pair (device ns, GPST) and b = 1 / (1 + drift) for a device clock running fast by
// `drift` (s/s). Fit (robust, pairs with outliers and jitter):
//   1. b0 = median of the slopes between pair i and pair i + n/2 (an outlier spoils one slope, not the median);
//      a0 = median of (y_i - b0 x_i), x_i = (t_ns,i - n_ref) 1e-9, y_i = t_gps,i - t_ref;
//   2. repeat: residuals r_i = y_i - a - b x_i, sigma = 1.4826 median|r_i|, inliers |r_i| <= max(k sigma, r_min),
//      least squares on the inliers, until the inlier set no longer changes (at most 20 times).
// Reported: a, b (as the drift in ppm), the inliers' residual RMS and largest residual, and the rejected pairs.
// Steps: a device whose clock or GPS time-sync jumps (a clock set, a receiver restart) gives pairs whose offset
// y - x changes at once and stays changed. A step is where consecutive pairs' offsets differ by more than
// max_residual_rms_s and the median offsets of up to 9 pairs on each side (at least 5 after it) differ by as much (a
// few outlier pairs are no step). The pairs are then fitted in pieces, one per stretch between steps (a piece of one
// pair takes the drift of the longest piece). Which piece maps a pose is the VIO's own clock's call: if its stamps
// step too at the same place (an interval off its rate by about the step: the device clock stepped), the poses from
// there take the new piece and the VIO track breaks (vio_track.hpp: stitched, as after a frame reset, or a new
// segment); if they do not, the time sync alone stepped (a receiver glitch, a restarted sync) and the poses keep the
// line they followed until a later piece comes back to it. The causal bridge does the same with the stamps of the
// poses it mapped in the last 30 s, once the step is seen (five pairs after it).
// One pair determines the offset only: b = 1 (drift taken as zero), with a warning. VIO already on GPST (t_ns =
// GPST nanoseconds since 1980-01-06 00:00:00) needs no pairs: TimeBridge::gps_clock().
//
// Whole file or causal. `canyon process` may fit all pairs of the file at once (whole_file). A live rover cannot:
// it maps each VIO pose with what it has received. CausalTimeBridge makes that deterministic: a pose at device time
// t_ns is mapped with the fit to the pairs whose device time is at most t_ns - hold (the last window_pairs of them),
// and only once a pair later than t_ns - hold has been seen (pairs arrive in device-time order, so none of the pairs
// it uses can still be on its way). With pairs every second and hold 1.5 s a pose waits for nothing in steady state,
// the fit is extrapolated by at most hold + 1 s, and files and DDS streams give the same mapping (canyon process with
// timesync_mode: causal equals the rover fed over DDS). At the start, until the first pair is hold old, a pose within
// hold of it takes that pair's offset alone (the drift over those seconds is microseconds): the VIO is used from the
// first pair on, as in whole_file. Pairs spanning less than 10 s whose fitted drift is beyond max_drift_ppm give the
// offset alone too (their slope is their jitter's, not the clock's).

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "canyon/core/result.hpp"
#include "canyon/core/time.hpp"
#include "canyon/io/vio_file.hpp"

namespace canyon::fusion {

struct TimeBridgeOptions {
  double outlier_sigmas = 4.0;            ///< k: a pair whose residual exceeds k robust sigmas is an outlier
  double min_outlier_threshold_s = 2e-3;  ///< r_min: residuals up to this are never outliers (s)
  double max_residual_rms_s = 0.02;       ///< a fit whose inliers' residual RMS is larger is refused (s)
  double max_drift_ppm = 1000.0;          ///< a fitted drift beyond this is refused (ppm)
  bool causal = false;                    ///< false: one fit to every pair (files); true: CausalTimeBridge
  double causal_hold_s = 1.5;             ///< causal: a pose uses the pairs at least this much older (s)
  int causal_window_pairs = 600;          ///< causal: at most this many of the latest such pairs

  /// Empty if valid, else the violated rule.
  [[nodiscard]] std::string validate() const;
};

/// Device clock -> GPST: one line, or one line per piece between the steps of the time sync.
class TimeBridge {
 public:
  /// One line of the map, used from device time from_ns on (the first piece also before it); after_ns: the device
  /// time of the previous piece's last pair (the step happened in (after_ns, from_ns]).
  struct Piece {
    std::int64_t from_ns = 0;
    double a_s = 0.0;
    double b = 1.0;
    std::int64_t after_ns = 0;
  };
  /// The identity for VIO stamped with GPST nanoseconds since the GPS epoch.
  static TimeBridge gps_clock();
  TimeBridge(std::int64_t reference_ns, core::GpsTime reference_time, double a_s, double b)
      : reference_ns_(reference_ns), reference_time_(reference_time), pieces_{Piece{reference_ns, a_s, b}} {}
  /// Pieces in increasing from_ns, at least one.
  TimeBridge(std::int64_t reference_ns, core::GpsTime reference_time, std::vector<Piece> pieces)
      : reference_ns_(reference_ns), reference_time_(reference_time), pieces_(std::move(pieces)) {}

  [[nodiscard]] core::GpsTime to_gps(std::int64_t t_ns) const;
  /// t_ns mapped by piece k, wherever t_ns lies.
  [[nodiscard]] core::GpsTime to_gps_with_piece(std::int64_t t_ns, int k) const;
  /// The piece that maps t_ns (0 with one piece).
  [[nodiscard]] int piece_of(std::int64_t t_ns) const;
  [[nodiscard]] int pieces() const { return static_cast<int>(pieces_.size()); }
  [[nodiscard]] const Piece& piece(int k) const { return pieces_[static_cast<std::size_t>(k)]; }
  /// GPST by piece k minus GPST by piece `from` at piece k's first pair (s).
  [[nodiscard]] double step_s(int k, int from) const;
  /// Of the first piece.
  [[nodiscard]] double offset_s() const { return gps_clock_ ? 0.0 : pieces_.front().a_s; }
  /// Device clock rate error: the device runs fast by this (1e-6), of the first piece.
  [[nodiscard]] double drift_ppm() const { return gps_clock_ ? 0.0 : (1.0 / pieces_.front().b - 1.0) * 1e6; }
  [[nodiscard]] bool is_gps_clock() const { return gps_clock_; }
  [[nodiscard]] std::int64_t reference_ns() const { return reference_ns_; }
  [[nodiscard]] const core::GpsTime& reference_time() const { return reference_time_; }

 private:
  TimeBridge() = default;
  /// t_ns on piece p's line.
  [[nodiscard]] core::GpsTime on_line(const Piece& p, std::int64_t t_ns) const;
  std::int64_t reference_ns_ = 0;
  core::GpsTime reference_time_;
  std::vector<Piece> pieces_;
  bool gps_clock_ = false;
};

/// A step of the time sync between two consecutive pairs.
struct TimeSyncStep {
  int line_before = 0;    ///< the last pair before it (line in the time-sync file)
  int line_after = 0;     ///< the first pair after it
  std::int64_t t_ns = 0;  ///< device time of the first pair after it
  double step_s = 0.0;    ///< the change of the GPST offset (s)
};

struct TimeBridgeFit {
  TimeBridge bridge = TimeBridge::gps_clock();
  int pairs = 0;
  std::vector<int> outlier_lines;   ///< lines of the rejected pairs in the time-sync file
  double residual_rms_s = 0.0;      ///< of the inliers
  double max_residual_s = 0.0;      ///< largest inlier residual (absolute)
  std::vector<TimeSyncStep> steps;  ///< where the pairs were split into pieces
  std::vector<std::string> warnings;
};

/// Whether a VIO stream's own stamps (device ns, increasing) show a step of the time sync between after_ns and from_ns:
/// two consecutive stamps there whose interval differs from the stream's nominal one by about -step_s (within half of
/// it). Then the device clock stepped, and the pieces map the poses right; otherwise only the time sync stepped and
/// which side of it is right cannot be told.
/// Returns the stamp after that interval (where the device clock's step is), if any.
std::optional<std::int64_t> vio_clock_shows_step(const std::vector<std::int64_t>& stamps_ns, std::int64_t after_ns,
                                                 std::int64_t from_ns, double step_s);

/// The line a VIO stream with these stamps follows from device time from_ns on: piece k's own when the VIO's stamps
/// show its step (the device clock stepped; from the VIO's own step on) or when it comes back to the line the VIO
/// followed before; else that line (the time sync alone stepped, and the VIO's clock, which did not, keeps it).
struct VioClockLine {
  std::int64_t from_ns = 0;
  int piece = 0;
};
/// One per piece of `bridge`, in device-time order.
std::vector<VioClockLine> lines_the_vio_follows(const TimeBridge& bridge, const std::vector<std::int64_t>& stamps_ns);

/// Fits the bridge to time-sync pairs (any order), in pieces where they step. Error if there is none, if all device
/// times are equal, or if in a piece the inliers' residual RMS or the drift is beyond the options' limits or fewer
/// than half the pairs are inliers.
Result<TimeBridgeFit> fit_time_bridge(const std::vector<io::TimeSyncPair>& pairs,
                                      const TimeBridgeOptions& options = {});

/// Device clock -> GPST for streams (see the top of this file): pairs and poses in device-time order each.
class CausalTimeBridge {
 public:
  explicit CausalTimeBridge(TimeBridgeOptions options) : options_(options) {}
  /// For VIO stamped with GPST nanoseconds: no pair needed, always ready.
  static CausalTimeBridge gps_clock();
  /// A pair received. Error (the pair is ignored) when it is not later than the previous one.
  Status add(const io::TimeSyncPair& pair);
  /// Every pair the mapping of t_ns uses has been received: a pair later than t_ns - hold has been seen.
  [[nodiscard]] bool ready(std::int64_t t_ns) const;
  /// GPST of device time t_ns (queries in increasing t_ns; older pairs are forgotten), or an error: no pair old
  /// enough yet (a pose more than hold before the first pair), or the fit refused (fit_time_bridge's reasons).
  Result<core::GpsTime> to_gps(std::int64_t t_ns);
  /// Pairs received so far.
  [[nodiscard]] std::uint64_t pairs_received() const { return received_; }
  /// The fit in use (nullopt before the first).
  [[nodiscard]] const std::optional<TimeBridgeFit>& fit() const { return fit_; }
  /// Steps of the time sync the VIO's own clock shows too, seen so far: a pose mapped after a new one (to_gps) is
  /// stitched to those before. A step it does not show is the time sync's alone: the poses keep the line before it
  /// until the fit comes back to that line (ignored_steps() counts them, ignored_step_note() says the last).
  [[nodiscard]] int steps_seen() const { return steps_seen_; }
  [[nodiscard]] int ignored_steps() const { return ignored_steps_; }
  [[nodiscard]] const std::string& ignored_step_note() const { return ignored_note_; }

 private:
  TimeBridgeOptions options_;
  bool gps_clock_ = false;
  std::deque<io::TimeSyncPair> pairs_;
  std::uint64_t received_ = 0;
  std::uint64_t dropped_ = 0;  // forgotten from the front of pairs_ (index of pairs_[0] among all received)
  // The fit in use and the pairs it was made from (indices among all received, [first, last]).
  std::optional<TimeBridgeFit> fit_;
  std::uint64_t fit_first_ = 0;
  std::uint64_t fit_last_ = 0;
  std::optional<Error> fit_error_;
  int steps_seen_ = 0;
  std::int64_t last_step_ns_ = 0;
  std::deque<std::int64_t> recent_stamps_ns_;  // the poses' device times of the last 30 s
  std::optional<TimeBridge> followed_;         // the line before a step the VIO's clock did not show (its last piece)
  int ignored_steps_ = 0;
  std::string ignored_note_;
};

}  // namespace canyon::fusion
