// VIO trajectory on GPST: segments, SE(3) interpolation, joint covariances (see vio_track.hpp).

#include "canyon/fusion/vio_track.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "canyon/core/constants.hpp"

namespace canyon::fusion {
namespace {

constexpr double kMinResetTraceM2 = 1e-4;  // covariance collapses are only resets from above this trace (m^2)

double position_trace_m2(const VioTrackSample& s) {
  return s.P.topLeftCorner<3, 3>().trace();
}

/// The VIO restarted its covariance (with its frame) between prev and s.
bool covariance_collapsed(const VioTrackSample& prev, const VioTrackSample& s, const VioTrackOptions& options) {
  const double prev_trace = position_trace_m2(prev);
  return prev_trace > kMinResetTraceM2 && position_trace_m2(s) < options.reset_covariance_ratio * prev_trace;
}

/// s is further from prev than max_speed_mps allows in dt_s.
bool moved_too_fast(const VioTrackSample& prev, const VioTrackSample& s, const VioTrackOptions& options, double dt_s) {
  return (s.T_OI.p - prev.T_OI.p).norm() > options.max_speed_mps * dt_s;
}

}  // namespace

std::string VioTrackOptions::validate() const {
  if (!(max_gap_s > 0.0)) return "max_gap_s must be > 0";
  if (!(max_speed_mps > 0.0)) return "max_speed_mps must be > 0";
  if (!(max_rotation_rate_dps > 0.0)) return "max_rotation_rate_dps must be > 0";
  if (!(reset_covariance_ratio >= 0.0 && reset_covariance_ratio < 1.0)) {
    return "reset_covariance_ratio must be in [0, 1)";
  }
  if (!(extrapolation_s >= 0.0)) return "extrapolation_s must be >= 0";
  if (!(interpolation_accel_mps2 >= 0.0)) return "interpolation_accel_mps2 must be >= 0";
  if (!(max_bridged_gap_s >= 0.0)) return "max_bridged_gap_s must be >= 0";
  return {};
}

double PoseIntervals::nominal_s(double dt_s) const {
  if (recent_.empty()) return std::min(dt_s, 1.0);
  std::vector<double> sorted = recent_;
  const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>((sorted.size() - 1) / 2);
  std::nth_element(sorted.begin(), middle, sorted.end());
  return *middle;
}

void PoseIntervals::add(double dt_s) {
  if (recent_.size() == static_cast<std::size_t>(kWindow)) recent_.erase(recent_.begin());
  recent_.push_back(dt_s);
}

double median_interval_s(const std::vector<VioTrackSample>& samples) {
  if (samples.size() < 2) return 0.0;
  std::vector<double> dt;
  dt.reserve(samples.size() - 1);
  for (std::size_t k = 1; k < samples.size(); ++k) dt.push_back(samples[k].t_s - samples[k - 1].t_s);
  const auto middle = dt.begin() + static_cast<std::ptrdiff_t>((dt.size() - 1) / 2);
  std::nth_element(dt.begin(), middle, dt.end());
  return *middle;
}

std::string segment_break(const VioTrackSample& prev, const VioTrackSample& s, const VioTrackOptions& options,
                          double nominal_interval_s, SegmentBreak* kind) {
  const auto set = [&](SegmentBreak k) {
    if (kind != nullptr) *kind = k;
  };
  set(SegmentBreak::None);
  const double dt_s = s.t_s - prev.t_s;
  const double jump_m = (s.T_OI.p - prev.T_OI.p).norm();
  const double turn_deg = core::so3_log(prev.T_OI.q.conjugate() * s.T_OI.q).norm() * core::kRadToDeg;
  char buffer[160];
  if (s.clock_piece != prev.clock_piece) {
    std::snprintf(buffer, sizeof buffer, "VIO time-sync step (%.2f s after the previous pose on GPST)", dt_s);
    set(SegmentBreak::TimeSyncStep);
    return buffer;
  }
  if (dt_s > std::max(options.max_gap_s, kGapIntervals * nominal_interval_s)) {
    std::snprintf(buffer, sizeof buffer, "VIO gap of %.2f s (poses %.2f s apart before it)", dt_s, nominal_interval_s);
    set(SegmentBreak::Gap);
    return buffer;
  }
  const bool jumped = moved_too_fast(prev, s, options, dt_s);
  if (jumped || turn_deg > options.max_rotation_rate_dps * dt_s) {
    std::snprintf(buffer, sizeof buffer, "VIO jump of %.2f m and %.1f deg in %.3f s (odometry frame reset)", jump_m,
                  turn_deg, dt_s);
    set(jumped ? SegmentBreak::Jump : SegmentBreak::Turn);
    return buffer;
  }
  if (covariance_collapsed(prev, s, options)) {
    std::snprintf(buffer, sizeof buffer, "VIO covariance reset (position trace %.3g -> %.3g m^2)",
                  position_trace_m2(prev), position_trace_m2(s));
    set(SegmentBreak::CovarianceReset);
    return buffer;
  }
  return {};
}

namespace {

/// A gap the stream comes back from in the same frame (see the top of vio_track.hpp): short enough, no faster than
/// max_speed_mps, no covariance collapse.
bool bridgeable_gap(const VioTrackSample& prev, const VioTrackSample& s, const VioTrackOptions& options, double dt_s) {
  return dt_s <= options.max_bridged_gap_s && !moved_too_fast(prev, s, options, dt_s) &&
         !covariance_collapsed(prev, s, options);
}

/// Stitches `s`, the first pose after a jump or reset, to `prev` (and `before_prev`, if of its segment, for the
/// extrapolation): `stitch` then maps every later pose of the new frame (see the top of vio_track.hpp).
void stitch_to(const VioTrackSample* before_prev, const VioTrackSample& prev, VioTrackSample& s,
               const VioTrackOptions& options, FrameStitch& stitch) {
  const double dt_s = s.t_s - prev.t_s;
  core::Pose predicted = prev.T_OI;
  if (before_prev != nullptr && before_prev->segment == prev.segment && prev.t_s > before_prev->t_s) {
    predicted = core::se3_interpolate(before_prev->T_OI, prev.T_OI, 1.0 + dt_s / (prev.t_s - before_prev->t_s));
  }
  const core::Pose given = s.T_OI;  // s as the VIO gave it
  const core::Matrix6d P_given = s.P;
  stitch.F = predicted * given.inverse();
  const double sigma_m = options.interpolation_accel_mps2 * dt_s * dt_s / 2.0;
  core::Matrix6d Q = core::Matrix6d::Zero();
  Q.topLeftCorner<3, 3>().diagonal().setConstant(std::max(sigma_m * sigma_m, 1e-8));
  s.T_OI = predicted;
  s.P = prev.P + Q;
  s.C_previous = prev.P;
  stitch.dP = s.P - P_given;
  ++stitch.count;
}

/// Gives `s` its segment after `prev` (nullptr: the first sample), its interval judged against `intervals` (which
/// it joins), in the frame `stitch` maps to; the reason and the new segment (or the stitch) in `note`.
void place_in_segment(const VioTrackSample* before_prev, const VioTrackSample* prev, VioTrackSample& s,
                      const VioTrackOptions& options, PoseIntervals& intervals, FrameStitch& stitch,
                      const core::GpsTime& reference, std::string* note) {
  if (prev == nullptr) {
    s.segment = 0;
    s.C_previous.setZero();
    return;
  }
  // The breaks are judged in the frame and covariances as the VIO gives them.
  const VioTrackSample* judged = prev;
  VioTrackSample prev_given;
  if (stitch.count > 0) {
    prev_given = *prev;
    prev_given.T_OI = stitch.F.inverse() * prev->T_OI;
    prev_given.P = prev->P - stitch.dP;
    judged = &prev_given;
  }
  const double dt_s = s.t_s - prev->t_s;
  SegmentBreak kind = SegmentBreak::None;
  const std::string why = segment_break(*judged, s, options, intervals.nominal_s(dt_s), &kind);
  intervals.add(dt_s);
  s.segment = prev->segment;
  if (why.empty()) {
    if (stitch.count > 0) {
      s.T_OI = stitch.F * s.T_OI;
      s.P += stitch.dP;
      s.C_previous += stitch.dP;
    }
    return;
  }
  const std::string where = " at " + core::format_gpst(reference + s.t_s, 3) + " (line " + std::to_string(s.line) + ")";
  if (kind == SegmentBreak::Gap && bridgeable_gap(*judged, s, options, dt_s)) {
    if (stitch.count > 0) {
      s.T_OI = stitch.F * s.T_OI;
      s.P += stitch.dP;
    }
    s.C_previous.setZero();  // the poses either side taken as uncorrelated
    if (note != nullptr) *note = why + where + ": bridged, the alignment kept (the same frame after it)";
    return;
  }
  // A jump or reset moved the VIO's frame; a time-sync step moved its poses in time (the frame is the same): either
  // way the device did not move, and the poses after it are stitched to the ones before.
  const bool stitchable =
      kind == SegmentBreak::Jump || kind == SegmentBreak::CovarianceReset || kind == SegmentBreak::TimeSyncStep;
  if (stitchable && options.stitch_frame_resets) {
    stitch_to(before_prev, *prev, s, options, stitch);
    if (note != nullptr) {
      *note = why + where + ": the new frame stitched to the old one (the device's pose taken as continuous), the " +
              "alignment kept";
    }
    return;
  }
  stitch = FrameStitch{};  // a new segment starts in the frame as given
  s.segment = prev->segment + 1;
  s.C_previous.setZero();  // no predecessor in its segment
  if (note != nullptr) *note = why + where + ": new VIO segment " + std::to_string(s.segment) + ", fusion re-aligns";
}

}  // namespace

void assign_segments(std::vector<VioTrackSample>& samples, const VioTrackOptions& options,
                     const core::GpsTime& reference, std::vector<std::string>* notes) {
  PoseIntervals intervals;
  FrameStitch stitch;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    std::string note;
    place_in_segment(k < 2 ? nullptr : &samples[k - 2], k == 0 ? nullptr : &samples[k - 1], samples[k], options,
                     intervals, stitch, reference, &note);
    if (notes != nullptr && !note.empty()) notes->push_back(note);
  }
}

Result<VioTrack> VioTrack::build(const io::VioFile& file, const TimeBridge& bridge, const VioTrackOptions& options,
                                 std::vector<std::string>& notes) {
  if (const std::string e = options.validate(); !e.empty()) return Error{"vio track: " + e};
  if (file.records.empty()) return Error{"no VIO pose"};
  const core::GpsTime reference = bridge.to_gps(file.records.front().t_ns);
  std::vector<VioTrackSample> samples;
  samples.reserve(file.records.size());
  std::vector<std::int64_t> stamps_ns;
  stamps_ns.reserve(file.records.size());
  for (const io::VioRecord& r : file.records) stamps_ns.push_back(r.t_ns);
  // After a step of the time sync that the VIO's own stamps do not show, the poses keep the line before it.
  const std::vector<VioClockLine> lines = lines_the_vio_follows(bridge, stamps_ns);
  int overlapped = 0;
  int kept_line = 0;
  std::size_t line = 0;
  for (const io::VioRecord& r : file.records) {
    VioTrackSample s;
    while (line + 1 < lines.size() && lines[line + 1].from_ns <= r.t_ns) ++line;
    const int piece = bridge.piece_of(r.t_ns);
    s.clock_piece = lines[line].piece;
    s.t_s = bridge.to_gps_with_piece(r.t_ns, s.clock_piece) - reference;
    if (s.clock_piece < piece) ++kept_line;
    // A clock fit cannot reorder poses, but after a time-sync step back in GPST the next piece's first poses fall
    // before the last ones mapped: those are left out.
    if (!samples.empty() && !(s.t_s > samples.back().t_s)) {
      ++overlapped;
      continue;
    }
    s.T_OI = r.T_OI;
    s.P = r.covariance;
    if (options.use_cross_covariance && r.cross_previous) s.C_previous = *r.cross_previous;
    s.line = r.line;
    samples.push_back(s);
  }
  assign_segments(samples, options, reference, &notes);
  if (kept_line > 0) {
    notes.push_back(std::to_string(kept_line) +
                    " VIO poses after a step of the time sync that the VIO's own clock does not show: mapped with the "
                    "line before it (the time sync alone stepped)");
  }
  if (overlapped > 0) {
    notes.push_back(std::to_string(overlapped) +
                    " VIO poses mapped to GPST no later than the pose before them (after a time-sync step): left out");
  }
  return VioTrack(std::move(samples), reference, options);
}

VioTrack VioTrack::from_samples(std::vector<VioTrackSample> samples, core::GpsTime reference,
                                const VioTrackOptions& options) {
  assign_segments(samples, options, reference, nullptr);
  return VioTrack(std::move(samples), reference, options);
}

VioTrack VioTrack::streaming(const VioTrackOptions& options) {
  return VioTrack({}, core::GpsTime{}, options);
}

bool VioTrack::append(const io::VioRecord& record, const core::GpsTime& t, std::string* note, int clock_piece) {
  if (samples_.empty() && forgotten_ == 0) reference_ = t;
  VioTrackSample s;
  s.t_s = t - reference_;
  s.clock_piece = clock_piece;
  if (!samples_.empty() && !(s.t_s > samples_.back().t_s)) return false;
  s.T_OI = record.T_OI;
  s.P = record.covariance;
  if (options_.use_cross_covariance && record.cross_previous) s.C_previous = *record.cross_previous;
  s.line = record.line;
  const std::size_t n = samples_.size();
  place_in_segment(n < 2 ? nullptr : &samples_[n - 2], n == 0 ? nullptr : &samples_[n - 1], s, options_, intervals_,
                   stitch_, reference_, note);
  samples_.push_back(s);
  return true;
}

void VioTrack::forget_before(const core::GpsTime& t) {
  const double t_s = t - reference_;
  // Keep the last sample before t (an interpolation at t may need it).
  const auto it = std::lower_bound(samples_.begin(), samples_.end(), t_s,
                                   [](const VioTrackSample& s, double value) { return s.t_s < value; });
  const auto drop = static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - samples_.begin() - 1, 0));
  // Erase in batches (a quarter of the track at least) so that appending stays amortised O(1).
  if (drop == 0 || drop < samples_.size() / 4) return;
  samples_.erase(samples_.begin(), samples_.begin() + static_cast<std::ptrdiff_t>(drop));
  forgotten_ += static_cast<int>(drop);
}

bool VioTrack::covers(const core::GpsTime& t) const {
  const double t_s = t - reference_;
  const auto it = std::upper_bound(samples_.begin(), samples_.end(), t_s,
                                   [](double value, const VioTrackSample& s) { return value < s.t_s; });
  if (it == samples_.end()) return false;
  const bool starts_segment = it == samples_.begin() ? forgotten_ == 0 : (it - 1)->segment != it->segment;
  return !starts_segment || it + 1 != samples_.end();
}

std::optional<VioPoseAt> VioTrack::pose_at(const core::GpsTime& t) const {
  if (samples_.empty()) return std::nullopt;
  const double t_s = t - reference_;
  // First sample after t.
  const auto it = std::upper_bound(samples_.begin(), samples_.end(), t_s,
                                   [](double value, const VioTrackSample& s) { return value < s.t_s; });
  auto upper = static_cast<int>(it - samples_.begin());
  int lower = upper - 1;
  const auto n = static_cast<int>(samples_.size());
  const auto same_segment = [&](int i, int j) {
    return i >= 0 && j < n &&
           samples_[static_cast<std::size_t>(i)].segment == samples_[static_cast<std::size_t>(j)].segment;
  };
  if (!same_segment(lower, upper)) {
    // Before the first sample of a segment or after its last: extrapolate a little from its first or last interval.
    if (upper < n && upper + 1 < n && same_segment(upper, upper + 1) &&
        samples_[static_cast<std::size_t>(upper)].t_s - t_s <= options_.extrapolation_s) {
      lower = upper;
      upper = upper + 1;
    } else if (lower >= 1 && same_segment(lower - 1, lower) &&
               t_s - samples_[static_cast<std::size_t>(lower)].t_s <= options_.extrapolation_s) {
      upper = lower;
      lower = lower - 1;
    } else {
      return std::nullopt;
    }
  }
  const VioTrackSample& s0 = samples_[static_cast<std::size_t>(lower)];
  const VioTrackSample& s1 = samples_[static_cast<std::size_t>(upper)];
  VioPoseAt p;
  p.t_s = t_s;
  p.lower = lower + forgotten_;  // counting the forgotten samples
  p.segment = s0.segment;
  p.a = (t_s - s0.t_s) / (s1.t_s - s0.t_s);
  p.T_OI = core::se3_interpolate(s0.T_OI, s1.T_OI, p.a, &p.J_lower, &p.J_upper);
  return p;
}

core::Matrix6d VioTrack::sample_covariance(int k, int l) const {
  if (k == l) return sample(k).P;
  if (k > l) return sample_covariance(l, k).transpose();
  if (l == k + 1) return sample(l).C_previous;
  // Propagate the earlier error through the relative motion D_l = T_l-1^-1 T_l: Sigma_kl = Sigma_k,l-1 Ad(D_l^-1)^T.
  core::Matrix6d sigma = sample(k + 1).C_previous;
  for (int m = k + 2; m <= l; ++m) {
    const core::Pose D = sample(m - 1).T_OI.inverse() * sample(m).T_OI;
    sigma = sigma * core::se3_adjoint(D.inverse()).transpose();
  }
  return sigma;
}

Matrix12d VioTrack::joint_covariance(const VioPoseAt& a, const VioPoseAt& b, bool with_interpolation) const {
  // xi(a) = J_a0 xi_i + J_a1 xi_i+1, xi(b) = J_b0 xi_j + J_b1 xi_j+1.
  const std::array<int, 4> index = {a.lower, a.lower + 1, b.lower, b.lower + 1};
  const std::array<const core::Matrix6d*, 4> J = {&a.J_lower, &a.J_upper, &b.J_lower, &b.J_upper};
  Matrix12d out = Matrix12d::Zero();
  for (int u = 0; u < 4; ++u) {
    for (int v = 0; v < 4; ++v) {
      const int row = u < 2 ? 0 : 6;
      const int col = v < 2 ? 0 : 6;
      out.block<6, 6>(row, col) +=
          *J[static_cast<std::size_t>(u)] *
          sample_covariance(index[static_cast<std::size_t>(u)], index[static_cast<std::size_t>(v)]) *
          J[static_cast<std::size_t>(v)]->transpose();
    }
  }
  const double sigma_a_m = with_interpolation ? interpolation_sigma_m(a) : 0.0;
  const double sigma_b_m = with_interpolation ? interpolation_sigma_m(b) : 0.0;
  out.topLeftCorner<3, 3>().diagonal().array() += sigma_a_m * sigma_a_m;
  out.block<3, 3>(6, 6).diagonal().array() += sigma_b_m * sigma_b_m;
  if (a.lower == b.lower) {
    // One interval, one missed acceleration: the two interpolation errors are fully correlated.
    out.block<3, 3>(0, 6).diagonal().array() += sigma_a_m * sigma_b_m;
    out.block<3, 3>(6, 0).diagonal().array() += sigma_a_m * sigma_b_m;
  }
  return 0.5 * (out + out.transpose());
}

double VioTrack::interpolation_sigma_m(const VioPoseAt& p) const {
  if (!(options_.interpolation_accel_mps2 > 0.0)) return 0.0;
  const int upper = p.lower + 1;
  if (p.lower < forgotten_ || upper - forgotten_ >= static_cast<int>(samples_.size())) return 0.0;
  const double dt_s = sample(upper).t_s - sample(p.lower).t_s;
  const double x = std::clamp(p.a, 0.0, 1.0);
  return options_.interpolation_accel_mps2 * x * (1.0 - x) * dt_s * dt_s / 2.0;
}

core::Matrix6d VioTrack::covariance(const VioPoseAt& a) const {
  return joint_covariance(a, a).topLeftCorner<6, 6>();
}

}  // namespace canyon::fusion
