// Device clock -> GPST (model and fit in time_bridge.hpp).

#include "canyon/fusion/time_bridge.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "canyon/core/statistics.hpp"

namespace canyon::fusion {
namespace {

constexpr int kMaxIterations = 20;
constexpr double kMadToSigma = 1.4826;
constexpr std::int64_t kNsPerWeek = std::int64_t{core::kSecondsPerWeek} * 1000000000;
constexpr std::int64_t kStampWindowNs = 30'000'000'000;  // the poses' stamps the causal bridge keeps (ns)
constexpr double kMinDriftSpanS = 10.0;                  // pairs spanning less do not refuse a fit for its drift (s)

/// The median of a copy: the callers keep their vectors' order.
double median(std::vector<double> v) {
  return core::median_in_place(v);
}

}  // namespace

std::string TimeBridgeOptions::validate() const {
  if (!(outlier_sigmas > 0.0)) return "outlier_sigmas must be > 0";
  if (!(min_outlier_threshold_s >= 0.0)) return "min_outlier_threshold_s must be >= 0";
  if (!(max_residual_rms_s > 0.0)) return "max_residual_rms_s must be > 0";
  if (!(max_drift_ppm > 0.0)) return "max_drift_ppm must be > 0";
  if (!(causal_hold_s >= 0.0)) return "causal_hold_s must be >= 0";
  if (causal_window_pairs < 1) return "causal_window_pairs must be >= 1";
  return {};
}

TimeBridge TimeBridge::gps_clock() {
  TimeBridge b;
  b.gps_clock_ = true;
  return b;
}

core::GpsTime TimeBridge::to_gps(std::int64_t t_ns) const {
  if (gps_clock_) {
    const std::int64_t week = t_ns / kNsPerWeek;
    const std::int64_t rest_ns = t_ns - week * kNsPerWeek;
    return core::GpsTime{static_cast<int>(week), static_cast<double>(rest_ns) * 1e-9}.normalized();
  }
  return to_gps_with_piece(t_ns, piece_of(t_ns));
}

core::GpsTime TimeBridge::on_line(const Piece& p, std::int64_t t_ns) const {
  const double x_s = static_cast<double>(t_ns - reference_ns_) * 1e-9;
  return reference_time_ + (p.a_s + p.b * x_s);
}

double TimeBridge::step_s(int k, int from) const {
  return on_line(piece(k), piece(k).from_ns) - on_line(piece(from), piece(k).from_ns);
}

std::optional<std::int64_t> vio_clock_shows_step(const std::vector<std::int64_t>& stamps_ns, std::int64_t after_ns,
                                                 std::int64_t from_ns, double step_s) {
  if (stamps_ns.size() < 3) return std::nullopt;
  std::vector<double> intervals_s;
  for (std::size_t i = 1; i < stamps_ns.size(); ++i) {
    intervals_s.push_back(static_cast<double>(stamps_ns[i] - stamps_ns[i - 1]) * 1e-9);
  }
  const double nominal_s = median(intervals_s);
  // The device clock's step lies between the pairs either side of the time sync's; one interval of slack each side.
  const auto slack_ns = static_cast<std::int64_t>(std::llround(nominal_s * 1e9));
  for (std::size_t i = 1; i < stamps_ns.size(); ++i) {
    if (stamps_ns[i] < after_ns - slack_ns || stamps_ns[i - 1] > from_ns + slack_ns) continue;
    const double jump_s = intervals_s[i - 1] - nominal_s;
    if (std::abs(jump_s + step_s) < 0.5 * std::abs(step_s)) return stamps_ns[i];
  }
  return std::nullopt;
}

std::vector<VioClockLine> lines_the_vio_follows(const TimeBridge& bridge, const std::vector<std::int64_t>& stamps_ns) {
  std::vector<VioClockLine> lines{VioClockLine{std::numeric_limits<std::int64_t>::min(), 0}};
  int line = 0;  // the piece whose line the VIO's clock follows
  for (int k = 1; k < bridge.pieces(); ++k) {
    const double back_s = bridge.step_s(k, line);
    const double step_s = bridge.step_s(k, k - 1);
    const std::optional<std::int64_t> shown =
        vio_clock_shows_step(stamps_ns, bridge.piece(k).after_ns, bridge.piece(k).from_ns, back_s);
    const bool back = std::abs(back_s) < 0.5 * std::abs(step_s);  // closer to the followed line than this step
    if (shown || back) line = k;
    lines.push_back(VioClockLine{shown ? std::min(*shown, bridge.piece(k).from_ns) : bridge.piece(k).from_ns, line});
  }
  return lines;
}

core::GpsTime TimeBridge::to_gps_with_piece(std::int64_t t_ns, int k) const {
  if (gps_clock_) return to_gps(t_ns);  // no pieces: the stamps are GPST
  return on_line(piece(std::max(k, 0)), t_ns);
}

int TimeBridge::piece_of(std::int64_t t_ns) const {
  int k = 0;
  while (k + 1 < static_cast<int>(pieces_.size()) && pieces_[static_cast<std::size_t>(k) + 1].from_ns <= t_ns) ++k;
  return k;
}

namespace {

/// One line y = a + b x fitted to pairs [begin, end) (robust start, then iterated least squares on the inliers; see
/// the header), with its inliers and their residuals.
struct LineFit {
  double a = 0.0;
  double b = 1.0;
  std::vector<bool> inlier;  // of [begin, end)
  int inliers = 0;
  double residual_rms_s = 0.0;
  double max_residual_s = 0.0;
};

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y, std::size_t begin, std::size_t end,
                 const TimeBridgeOptions& options) {
  const std::size_t n = end - begin;
  // 1. Robust start: median slope between pairs half the set apart, median intercept.
  std::vector<double> slopes;
  const std::size_t half = std::max<std::size_t>(n / 2, 1);
  for (std::size_t i = begin; i + half < end; ++i) {
    const double dx = x[i + half] - x[i];
    if (dx > 0.0) slopes.push_back((y[i + half] - y[i]) / dx);
  }
  if (slopes.empty()) {
    for (std::size_t i = begin + 1; i < end; ++i) {
      if (x[i] > x[begin]) slopes.push_back((y[i] - y[begin]) / (x[i] - x[begin]));
    }
  }
  LineFit fit;
  double b = median(slopes);
  std::vector<double> intercepts(n);
  for (std::size_t i = 0; i < n; ++i) intercepts[i] = y[begin + i] - b * x[begin + i];
  double a = median(intercepts);

  // 2. Iterated least squares on the inliers of a robust threshold.
  std::vector<bool> inlier(n, true);
  std::vector<double> abs_residual(n);
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    for (std::size_t i = 0; i < n; ++i) abs_residual[i] = std::abs(y[begin + i] - a - b * x[begin + i]);
    const double sigma = kMadToSigma * median(abs_residual);
    const double threshold = std::max(options.outlier_sigmas * sigma, options.min_outlier_threshold_s);
    std::vector<bool> next(n);
    double sw = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      next[i] = abs_residual[i] <= threshold;
      if (!next[i]) continue;
      sw += 1.0;
      sx += x[begin + i];
      sy += y[begin + i];
      sxx += x[begin + i] * x[begin + i];
      sxy += x[begin + i] * y[begin + i];
    }
    const double det = sw * sxx - sx * sx;
    if (sw < 2.0 || !(det > 0.0)) break;
    b = (sw * sxy - sx * sy) / det;
    a = (sy - b * sx) / sw;
    const bool same = next == inlier;
    inlier = std::move(next);
    if (same && iteration > 0) break;
  }
  double sum2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!inlier[i]) continue;
    const double r = std::abs(y[begin + i] - a - b * x[begin + i]);
    sum2 += r * r;
    fit.max_residual_s = std::max(fit.max_residual_s, r);
    ++fit.inliers;
  }
  fit.residual_rms_s = fit.inliers > 0 ? std::sqrt(sum2 / fit.inliers) : 0.0;
  fit.a = a;
  fit.b = b;
  fit.inlier = std::move(inlier);
  return fit;
}

/// Where the pairs step (see the header): the indices that start a new piece.
std::vector<std::size_t> find_steps(const std::vector<double>& x, const std::vector<double>& y, double threshold_s) {
  constexpr std::size_t kSide = 9;      // pairs on each side whose median offsets must differ
  constexpr std::size_t kMinAfter = 5;  // pairs after a step before it counts (a few late outliers are no step)
  const std::size_t n = x.size();
  const auto offset = [&](std::size_t i) { return y[i] - x[i]; };
  const auto median_offset = [&](std::size_t from, std::size_t to) {
    std::vector<double> d;
    for (std::size_t i = from; i < to; ++i) d.push_back(offset(i));
    return median(d);
  };
  std::vector<std::size_t> starts;
  for (std::size_t i = 1; i + kMinAfter <= n; ++i) {
    if (std::abs(offset(i) - offset(i - 1)) <= threshold_s) continue;
    const std::size_t piece_start = starts.empty() ? 0 : starts.back();
    const std::size_t from = std::max(piece_start, i >= kSide ? i - kSide : 0);
    const std::size_t to = std::min(n, i + kSide);
    if (std::abs(median_offset(i, to) - median_offset(from, i)) > threshold_s) starts.push_back(i);
  }
  return starts;
}

/// The rules a piece's fit must meet (header), as an error naming the piece's lines when there are several.
std::optional<Error> check_piece(const LineFit& line, std::size_t pairs, const std::string& where,
                                 const TimeBridgeOptions& options) {
  if (2 * line.inliers < static_cast<int>(pairs)) {
    return Error{"time sync" + where + ": only " + std::to_string(line.inliers) + " of " + std::to_string(pairs) +
                 " pairs agree on one clock offset and drift"};
  }
  if (line.residual_rms_s > options.max_residual_rms_s) {
    return Error{"time sync" + where + ": residual RMS " + std::to_string(line.residual_rms_s * 1e3) + " ms exceeds " +
                 std::to_string(options.max_residual_rms_s * 1e3) + " ms"};
  }
  const double drift_ppm = (1.0 / line.b - 1.0) * 1e6;
  if (std::abs(drift_ppm) > options.max_drift_ppm) {
    return Error{"time sync" + where + ": fitted device clock drift " + std::to_string(drift_ppm) +
                 " ppm is beyond the " + std::to_string(options.max_drift_ppm) + " ppm allowed"};
  }
  return std::nullopt;
}

}  // namespace

Result<TimeBridgeFit> fit_time_bridge(const std::vector<io::TimeSyncPair>& input, const TimeBridgeOptions& options) {
  if (const std::string e = options.validate(); !e.empty()) return Error{"time bridge: " + e};
  if (input.empty()) return Error{"no time-sync pair to map the VIO clock to GPST"};
  std::vector<io::TimeSyncPair> pairs = input;
  std::sort(pairs.begin(), pairs.end(), [](const auto& l, const auto& r) { return l.t_ns < r.t_ns; });
  const std::int64_t n_ref = pairs.front().t_ns;
  const core::GpsTime t_ref = pairs.front().time;
  const auto n = pairs.size();
  std::vector<double> x(n), y(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = static_cast<double>(pairs[i].t_ns - n_ref) * 1e-9;
    y[i] = pairs[i].time - t_ref;
  }
  TimeBridgeFit fit;
  fit.pairs = static_cast<int>(n);
  if (n == 1) {
    fit.bridge = TimeBridge(n_ref, t_ref, 0.0, 1.0);
    fit.warnings.emplace_back(
        "one time-sync pair: the VIO clock offset is known, its drift is not and is taken as zero (a 50 ppm drift "
        "then shifts the VIO by 5 ms after 100 s)");
    return fit;
  }
  if (x.back() <= 0.0) return Error{"all time-sync pairs have the same device time: no clock rate can be fitted"};

  std::vector<std::size_t> starts = find_steps(x, y, options.max_residual_rms_s);
  starts.insert(starts.begin(), 0);
  const std::size_t pieces = starts.size();
  const auto piece_end = [&](std::size_t k) { return k + 1 < pieces ? starts[k + 1] : n; };
  std::vector<LineFit> lines(pieces);
  std::size_t longest = 0;
  for (std::size_t k = 0; k < pieces; ++k) {
    if (piece_end(k) - starts[k] >= 2) lines[k] = fit_line(x, y, starts[k], piece_end(k), options);
    if (piece_end(k) - starts[k] > piece_end(longest) - starts[longest]) longest = k;
  }
  std::vector<TimeBridge::Piece> map;
  double sum2 = 0.0;
  int inliers = 0;
  for (std::size_t k = 0; k < pieces; ++k) {
    const std::size_t begin = starts[k];
    const std::size_t end = piece_end(k);
    LineFit& line = lines[k];
    if (end - begin < 2) {
      // One pair: the offset only, with the drift of the longest piece.
      line.b = lines[longest].b;
      line.a = y[begin] - line.b * x[begin];
      line.inlier.assign(1, true);
    } else {
      const std::string where = pieces == 1 ? std::string{}
                                            : " (pairs at lines " + std::to_string(pairs[begin].line) + " to " +
                                                  std::to_string(pairs[end - 1].line) + ")";
      const bool short_span = x[end - 1] - x[begin] < kMinDriftSpanS;
      if (short_span && std::abs((1.0 / line.b - 1.0) * 1e6) > options.max_drift_ppm) {
        // A few pairs close together fit the drift to their jitter (2 pairs 1 s apart with 0.5 ms jitter: +-700
        // ppm): beyond the limit it is not the clock's, so the offset is taken alone.
        std::vector<double> offsets;
        for (std::size_t i = begin; i < end; ++i) offsets.push_back(y[i] - x[i]);
        line.b = 1.0;
        line.a = median(offsets);
        double sum2 = 0.0;
        for (const double d : offsets) sum2 += (d - line.a) * (d - line.a);
        line.residual_rms_s = std::sqrt(sum2 / static_cast<double>(offsets.size()));
        line.inlier.assign(end - begin, true);
        line.inliers = static_cast<int>(end - begin);
        fit.warnings.emplace_back("time-sync pairs spanning less than " + std::to_string(kMinDriftSpanS) +
                                  " s fit a drift beyond the limit: the offset is taken alone");
      }
      if (auto e = check_piece(line, end - begin, where, options)) return *e;
    }
    for (std::size_t i = begin; i < end; ++i) {
      if (!line.inlier[i - begin]) {
        fit.outlier_lines.push_back(pairs[i].line);
        continue;
      }
      const double r = std::abs(y[i] - line.a - line.b * x[i]);
      sum2 += r * r;
      fit.max_residual_s = std::max(fit.max_residual_s, r);
      ++inliers;
    }
    map.push_back(TimeBridge::Piece{pairs[begin].t_ns, line.a, line.b, begin > 0 ? pairs[begin - 1].t_ns : 0});
    if (k > 0) {
      const double step_s = (line.a + line.b * x[begin]) - (lines[k - 1].a + lines[k - 1].b * x[begin]);
      fit.steps.push_back(TimeSyncStep{pairs[begin - 1].line, pairs[begin].line, pairs[begin].t_ns, step_s});
    }
  }
  fit.residual_rms_s = inliers > 0 ? std::sqrt(sum2 / inliers) : 0.0;
  fit.bridge = TimeBridge(n_ref, t_ref, std::move(map));
  for (const TimeSyncStep& step : fit.steps) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "the GPST of the device clock steps by %+.3f s between the pairs at lines %d and %d: fitted in "
                  "pieces; the VIO takes the new piece if its own stamps step too (the device clock stepped), else "
                  "it keeps the line before (the time sync alone stepped)",
                  step.step_s, step.line_before, step.line_after);
    fit.warnings.emplace_back(text);
  }
  return fit;
}

CausalTimeBridge CausalTimeBridge::gps_clock() {
  CausalTimeBridge b{TimeBridgeOptions{}};
  b.gps_clock_ = true;
  return b;
}

Status CausalTimeBridge::add(const io::TimeSyncPair& pair) {
  if (!pairs_.empty() && !(pair.t_ns > pairs_.back().t_ns)) {
    return Error{"time-sync pair at device time " + std::to_string(pair.t_ns) + " ns is not after the previous one (" +
                 std::to_string(pairs_.back().t_ns) + " ns): ignored"};
  }
  pairs_.push_back(pair);
  ++received_;
  return Ok{};
}

bool CausalTimeBridge::ready(std::int64_t t_ns) const {
  if (gps_clock_) return true;
  const auto hold_ns = static_cast<std::int64_t>(std::llround(options_.causal_hold_s * 1e9));
  return !pairs_.empty() && pairs_.back().t_ns > t_ns - hold_ns;
}

Result<core::GpsTime> CausalTimeBridge::to_gps(std::int64_t t_ns) {
  if (gps_clock_) return TimeBridge::gps_clock().to_gps(t_ns);
  recent_stamps_ns_.push_back(t_ns);
  while (t_ns - recent_stamps_ns_.front() > kStampWindowNs) recent_stamps_ns_.pop_front();
  const auto hold_ns = static_cast<std::int64_t>(std::llround(options_.causal_hold_s * 1e9));
  const std::int64_t cutoff_ns = t_ns - hold_ns;
  // The pairs at or before the cutoff: [0, end) of pairs_; the fit takes the last window of them.
  const auto end =
      static_cast<std::size_t>(std::upper_bound(pairs_.begin(), pairs_.end(), cutoff_ns,
                                                [](std::int64_t t, const io::TimeSyncPair& p) { return t < p.t_ns; }) -
                               pairs_.begin());
  if (end == 0) {
    // The start: until the first pair is hold old, a pose within hold of it takes its offset alone (the drift over
    // those seconds is a few microseconds at most), instead of waiting for pairs that can never be older.
    if (!pairs_.empty() && dropped_ == 0 && t_ns >= pairs_.front().t_ns - hold_ns) {
      const io::TimeSyncPair& first = pairs_.front();
      return first.time + static_cast<double>(t_ns - first.t_ns) * 1e-9;
    }
    return Error{"no time-sync pair " + std::to_string(options_.causal_hold_s) +
                 " s before the VIO pose yet (device time " + std::to_string(t_ns) + " ns)"};
  }
  const std::size_t window = static_cast<std::size_t>(options_.causal_window_pairs);
  const std::size_t begin = end > window ? end - window : 0;
  // Queries come in increasing t_ns: pairs before the window are never used again.
  pairs_.erase(pairs_.begin(), pairs_.begin() + static_cast<std::ptrdiff_t>(begin));
  dropped_ += begin;
  const std::uint64_t first = dropped_;
  const std::uint64_t last = dropped_ + (end - begin) - 1;
  if (!(fit_ || fit_error_) || first != fit_first_ || last != fit_last_) {
    const std::vector<io::TimeSyncPair> used(pairs_.begin(), pairs_.begin() + static_cast<std::ptrdiff_t>(end - begin));
    auto fit = fit_time_bridge(used, options_);
    fit_first_ = first;
    fit_last_ = last;
    if (fit) {
      fit_ = std::move(*fit);
      fit_error_.reset();
    } else {
      fit_error_ = fit.error();
    }
  }
  if (fit_error_) return *fit_error_;
  const TimeBridge& bridge = fit_->bridge;
  if (bridge.pieces() > 1 && bridge.piece(bridge.pieces() - 1).from_ns > last_step_ns_) {
    // A new step: the device clock's (the poses' stamps show it: stitched) or the time sync's alone (refused).
    const int k = bridge.pieces() - 1;
    last_step_ns_ = bridge.piece(k).from_ns;
    const double step_s = bridge.step_s(k, k - 1);
    const std::vector<std::int64_t> stamps(recent_stamps_ns_.begin(), recent_stamps_ns_.end());
    if (followed_) {
      // Keeping a line already: this step may come back to it (below).
    } else if (vio_clock_shows_step(stamps, bridge.piece(k).after_ns, bridge.piece(k).from_ns, step_s).has_value()) {
      ++steps_seen_;
    } else {
      followed_ = TimeBridge(bridge.reference_ns(), bridge.reference_time(), {bridge.piece(k - 1)});
      ++ignored_steps_;
      char text[240];
      std::snprintf(text, sizeof text,
                    "the time sync stepped by %+.3f s at device time %.3f s but the VIO's own clock did not: the VIO "
                    "keeps the mapping before it until the sync comes back",
                    step_s, static_cast<double>(bridge.piece(k).from_ns) * 1e-9);
      ignored_note_ = text;
    }
  }
  const core::GpsTime t = bridge.to_gps(t_ns);
  if (followed_) {
    const core::GpsTime kept = followed_->to_gps(t_ns);
    if (std::abs(t - kept) > options_.max_residual_rms_s) return kept;
    followed_.reset();  // the sync came back to the line the VIO follows
  }
  return t;
}

}  // namespace canyon::fusion
