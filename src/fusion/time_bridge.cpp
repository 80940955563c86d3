// Device clock -> GPST (model and fit in time_bridge.hpp).

#include "canyon/fusion/time_bridge.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "canyon/core/statistics.hpp"

namespace canyon::fusion {
namespace {

constexpr int kMaxIterations = 20;
constexpr double kMadToSigma = 1.4826;
constexpr std::int64_t kNsPerWeek = std::int64_t{core::kSecondsPerWeek} * 1000000000;

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
  const double x_s = static_cast<double>(t_ns - reference_ns_) * 1e-9;
  return reference_time_ + (a_s_ + b_ * x_s);
}

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

  // 1. Robust start: median slope between pairs half the set apart, median intercept.
  std::vector<double> slopes;
  const std::size_t half = std::max<std::size_t>(n / 2, 1);
  for (std::size_t i = 0; i + half < n; ++i) {
    const double dx = x[i + half] - x[i];
    if (dx > 0.0) slopes.push_back((y[i + half] - y[i]) / dx);
  }
  if (slopes.empty()) {
    for (std::size_t i = 1; i < n; ++i) {
      if (x[i] > x[0]) slopes.push_back((y[i] - y[0]) / (x[i] - x[0]));
    }
  }
  double b = median(slopes);
  std::vector<double> intercepts(n);
  for (std::size_t i = 0; i < n; ++i) intercepts[i] = y[i] - b * x[i];
  double a = median(intercepts);

  // 2. Iterated least squares on the inliers of a robust threshold.
  std::vector<bool> inlier(n, true);
  std::vector<double> abs_residual(n);
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    for (std::size_t i = 0; i < n; ++i) abs_residual[i] = std::abs(y[i] - a - b * x[i]);
    const double sigma = kMadToSigma * median(abs_residual);
    const double threshold = std::max(options.outlier_sigmas * sigma, options.min_outlier_threshold_s);
    std::vector<bool> next(n);
    double sw = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      next[i] = abs_residual[i] <= threshold;
      if (!next[i]) continue;
      sw += 1.0;
      sx += x[i];
      sy += y[i];
      sxx += x[i] * x[i];
      sxy += x[i] * y[i];
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
  int inliers = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = std::abs(y[i] - a - b * x[i]);
    if (!inlier[i]) {
      fit.outlier_lines.push_back(pairs[i].line);
      continue;
    }
    sum2 += r * r;
    fit.max_residual_s = std::max(fit.max_residual_s, r);
    ++inliers;
  }
  fit.residual_rms_s = inliers > 0 ? std::sqrt(sum2 / inliers) : 0.0;
  fit.bridge = TimeBridge(n_ref, t_ref, a, b);
  if (2 * inliers < static_cast<int>(n)) {
    return Error{"time sync: only " + std::to_string(inliers) + " of " + std::to_string(n) +
                 " pairs agree on one clock offset and drift"};
  }
  if (fit.residual_rms_s > options.max_residual_rms_s) {
    return Error{"time sync: residual RMS " + std::to_string(fit.residual_rms_s * 1e3) + " ms exceeds " +
                 std::to_string(options.max_residual_rms_s * 1e3) + " ms"};
  }
  if (std::abs(fit.bridge.drift_ppm()) > options.max_drift_ppm) {
    return Error{"time sync: fitted device clock drift " + std::to_string(fit.bridge.drift_ppm()) +
                 " ppm is beyond the " + std::to_string(options.max_drift_ppm) + " ppm allowed"};
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
  const auto hold_ns = static_cast<std::int64_t>(std::llround(options_.causal_hold_s * 1e9));
  const std::int64_t cutoff_ns = t_ns - hold_ns;
  // The pairs at or before the cutoff: [0, end) of pairs_; the fit takes the last window of them.
  const auto end =
      static_cast<std::size_t>(std::upper_bound(pairs_.begin(), pairs_.end(), cutoff_ns,
                                                [](std::int64_t t, const io::TimeSyncPair& p) { return t < p.t_ns; }) -
                               pairs_.begin());
  if (end == 0) {
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
  return fit_->bridge.to_gps(t_ns);
}

}  // namespace canyon::fusion
