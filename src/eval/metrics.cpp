#include "canyon/eval/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include <Eigen/Cholesky>

#include "canyon/core/geodesy.hpp"
#include "canyon/core/protection_level.hpp"
#include "canyon/io/pos_file.hpp"

namespace canyon::eval {
namespace {

/// One epoch's error in ENU at the truth point.
struct EpochError {
  StatusClass status_class = StatusClass::Other;
  Eigen::Vector3d d_N_m = Eigen::Vector3d::Zero();
};

double percentile_sorted(const std::vector<double>& sorted, double fraction) {
  const double rank = fraction * static_cast<double>(sorted.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(rank));
  const std::size_t above = std::min(below + 1, sorted.size() - 1);
  const double weight = rank - static_cast<double>(below);
  return sorted[below] + weight * (sorted[above] - sorted[below]);
}

/// The distribution of `values` (sorted in place).
ErrorDistribution distribution(std::vector<double>& values) {
  ErrorDistribution d;
  if (values.empty()) return d;
  std::sort(values.begin(), values.end());
  const auto n = static_cast<double>(values.size());
  double sum = 0.0;
  double sum_sq = 0.0;
  for (const double v : values) {
    sum += v;
    sum_sq += v * v;
  }
  d.mean_m = sum / n;
  d.rmse_m = std::sqrt(sum_sq / n);
  double sum_sq_dev = 0.0;
  for (const double v : values) sum_sq_dev += (v - d.mean_m) * (v - d.mean_m);
  d.std_m = std::sqrt(sum_sq_dev / n);
  d.median_m = percentile_sorted(values, 0.5);
  d.p95_m = percentile_sorted(values, 0.95);
  d.max_m = values.back();
  return d;
}

/// Accumulates errors of one set of epochs.
class ErrorAccumulator {
 public:
  void add(const Eigen::Vector3d& d_N_m) {
    const double horizontal_m = std::hypot(d_N_m.x(), d_N_m.y());
    sum_sq_vertical_m2_ += d_N_m.z() * d_N_m.z();
    errors_horizontal_m_.push_back(horizontal_m);
    errors_3d_m_.push_back(d_N_m.norm());
  }

  [[nodiscard]] ErrorStats finish() {
    ErrorStats s;
    s.count = static_cast<int>(errors_3d_m_.size());
    if (s.count == 0) return s;
    s.ape_3d = distribution(errors_3d_m_);
    s.ape_horizontal = distribution(errors_horizontal_m_);
    s.horizontal_rmse_m = s.ape_horizontal.rmse_m;
    s.horizontal_max_m = s.ape_horizontal.max_m;
    s.vertical_rmse_m = std::sqrt(sum_sq_vertical_m2_ / s.count);
    s.rmse_3d_m = s.ape_3d.rmse_m;
    s.max_3d_m = s.ape_3d.max_m;
    s.p95_3d_m = s.ape_3d.p95_m;
    return s;
  }

 private:
  double sum_sq_vertical_m2_ = 0.0;
  std::vector<double> errors_horizontal_m_;
  std::vector<double> errors_3d_m_;
};

bool has_solution(const core::Solution& s) {
  return s.status != core::SolutionStatus::None;
}

/// Indices of `solutions` sorted by time; Error if two are within `tolerance_s` of each other.
Result<std::vector<std::size_t>> sorted_by_time(const std::vector<core::Solution>& solutions, double tolerance_s) {
  std::vector<std::size_t> order(solutions.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](std::size_t i, std::size_t j) { return solutions[i].time < solutions[j].time; });
  for (std::size_t k = 1; k < order.size(); ++k) {
    const double dt_s = solutions[order[k]].time - solutions[order[k - 1]].time;
    if (dt_s <= tolerance_s) {
      return Error{"two solutions " + std::to_string(dt_s) + " s apart (records " + std::to_string(order[k - 1] + 1) +
                   " and " + std::to_string(order[k] + 1) + "), within the matching tolerance"};
    }
  }
  return order;
}

double ratio(int count, int total) {
  return total > 0 ? static_cast<double>(count) / total : 0.0;
}

void append_format(std::string& out, const char* format, auto... args) {
  char buffer[256];
  const int n = std::snprintf(buffer, sizeof buffer, format, args...);
  if (n > 0) out.append(buffer, std::min<std::size_t>(static_cast<std::size_t>(n), sizeof buffer - 1));
}

void append_error_columns(std::string& out, const ErrorStats& e) {
  if (e.count == 0) {
    append_format(out, " %6s %8s %8s %8s %8s %8s", "-", "-", "-", "-", "-", "-");
    return;
  }
  append_format(out, " %6d %8.3f %8.3f %8.3f %8.3f %8.3f", e.count, e.horizontal_rmse_m, e.vertical_rmse_m, e.rmse_3d_m,
                e.max_3d_m, e.p95_3d_m);
}

/// Counts the solution in SolutionStats::epochs_with_covariance and, when e^T C^-1 e > 9, beyond_3_sigma_horizontal;
/// when |e| exceeds its protection level, beyond_protection_level.
void count_beyond_3_sigma(const core::Solution& s, const core::Geodetic& truth, const Eigen::Vector3d& d_N_m,
                          SolutionStats& stats) {
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(truth);
  const Eigen::Matrix2d C = (R_NE * s.P_E_m2 * R_NE.transpose()).topLeftCorner<2, 2>();
  const Eigen::LLT<Eigen::Matrix2d> llt(0.5 * (C + C.transpose()));
  if (!C.allFinite() || llt.info() != Eigen::Success) return;
  ++stats.epochs_with_covariance;
  const Eigen::Vector2d e = d_N_m.head<2>();
  if (e.dot(llt.solve(e)) > 9.0) ++stats.beyond_3_sigma_horizontal;
  if (e.norm() > core::horizontal_protection_level_m(C)) ++stats.beyond_protection_level;
}

}  // namespace

std::string EvalOptions::validate() const {
  if (!(wrong_fix_threshold_m > 0.0)) return "wrong_fix_threshold_m > 0";
  if (!(time_tolerance_s > 0.0)) return "time_tolerance_s > 0";
  if (epochs_in && *epochs_in < 0) return "epochs_in >= 0";
  return {};
}

StatusClass status_class(core::SolutionStatus status) {
  switch (status) {
    case core::SolutionStatus::Fixed: return StatusClass::Fixed;
    case core::SolutionStatus::Float: return StatusClass::Float;
    case core::SolutionStatus::Single: return StatusClass::Single;
    case core::SolutionStatus::VioFillIn: return StatusClass::VioFillIn;
    default: return StatusClass::Other;
  }
}

const char* status_class_name(StatusClass c) {
  switch (c) {
    case StatusClass::Fixed: return "fixed";
    case StatusClass::Float: return "float";
    case StatusClass::Single: return "single";
    case StatusClass::VioFillIn: return "vio";
    case StatusClass::Other: return "other";
  }
  return "?";
}

Result<SolutionStats> evaluate(const std::vector<core::Solution>& solutions, const Truth* truth,
                               const EvalOptions& options) {
  if (const std::string broken = options.validate(); !broken.empty()) {
    return Error{"invalid evaluation options: violated constraint " + broken};
  }
  auto order = sorted_by_time(solutions, options.time_tolerance_s);
  if (!order) return order.error();

  SolutionStats stats;
  stats.has_truth = truth != nullptr;
  stats.wrong_fix_threshold_m = options.wrong_fix_threshold_m;
  stats.epochs_in = options.epochs_in.value_or(static_cast<int>(solutions.size()));
  std::array<ErrorAccumulator, kNumStatusClasses> class_errors;
  ErrorAccumulator overall_errors;
  std::optional<core::GpsTime> first_epoch = options.first_epoch;

  for (const std::size_t i : *order) {
    const core::Solution& s = solutions[i];
    if (!first_epoch) first_epoch = s.time;
    if (!has_solution(s)) continue;
    ++stats.epochs_with_solution;
    const StatusClass c = status_class(s.status);
    ++stats.by_class[static_cast<std::size_t>(c)].epochs;
    if (c == StatusClass::Fixed && !stats.time_to_first_fix_s) stats.time_to_first_fix_s = s.time - *first_epoch;
    if (truth == nullptr) continue;
    const auto p_E_truth_m = truth->position_at(s.time);
    if (!p_E_truth_m) continue;
    ++stats.epochs_with_truth;
    const core::Geodetic at_truth = core::ecef_to_geodetic(*p_E_truth_m);
    const Eigen::Vector3d d_N_m = core::ecef_to_enu(s.p_E_m - *p_E_truth_m, at_truth);
    class_errors[static_cast<std::size_t>(c)].add(d_N_m);
    overall_errors.add(d_N_m);
    if (c == StatusClass::Fixed && d_N_m.norm() > options.wrong_fix_threshold_m) ++stats.wrong_fixes;
    count_beyond_3_sigma(s, at_truth, d_N_m, stats);
  }
  for (std::size_t k = 0; k < kNumStatusClasses; ++k) {
    StatusStats& st = stats.by_class[k];
    st.fraction_of_solved = ratio(st.epochs, stats.epochs_with_solution);
    st.fraction_of_epochs_in = ratio(st.epochs, stats.epochs_in);
    st.error = class_errors[k].finish();
  }
  stats.overall = overall_errors.finish();
  if (truth != nullptr) stats.epochs_without_truth = stats.epochs_with_solution - stats.epochs_with_truth;
  return stats;
}

Result<Agreement> compare(const std::vector<core::Solution>& a, const std::vector<core::Solution>& b,
                          double time_tolerance_s) {
  if (!(time_tolerance_s > 0.0)) return Error{"comparison time tolerance must be > 0"};
  auto order_a = sorted_by_time(a, time_tolerance_s);
  if (!order_a) return Error{"first solution set: " + order_a.error().message};
  auto order_b = sorted_by_time(b, time_tolerance_s);
  if (!order_b) return Error{"second solution set: " + order_b.error().message};

  Agreement out;
  out.epochs_a = static_cast<int>(std::count_if(a.begin(), a.end(), has_solution));
  out.epochs_b = static_cast<int>(std::count_if(b.begin(), b.end(), has_solution));
  double sum_sq_fixed_m2 = 0.0;
  std::size_t j = 0;
  for (const std::size_t i : *order_a) {
    const core::Solution& sa = a[i];
    // Skip b epochs earlier than sa by more than the tolerance; sets are sorted, so at most one b can match.
    while (j < order_b->size() && b[(*order_b)[j]].time - sa.time < -time_tolerance_s) ++j;
    if (j == order_b->size()) break;
    const core::Solution& sb = b[(*order_b)[j]];
    if (std::abs(sb.time - sa.time) > time_tolerance_s) continue;
    if (!has_solution(sa) || !has_solution(sb)) continue;
    ++out.matched;
    const double distance_m = (sa.p_E_m - sb.p_E_m).norm();
    out.max_distance_matched_m = std::max(out.max_distance_matched_m, distance_m);
    const bool fixed_a = sa.status == core::SolutionStatus::Fixed;
    const bool fixed_b = sb.status == core::SolutionStatus::Fixed;
    if (fixed_a && fixed_b) {
      ++out.both_fixed;
      sum_sq_fixed_m2 += distance_m * distance_m;
      out.max_distance_fixed_m = std::max(out.max_distance_fixed_m, distance_m);
    } else if (fixed_a) {
      ++out.only_a_fixed;
    } else if (fixed_b) {
      ++out.only_b_fixed;
    }
  }
  if (out.both_fixed > 0) out.rms_distance_fixed_m = std::sqrt(sum_sq_fixed_m2 / out.both_fixed);
  return out;
}

std::string format_stats(const SolutionStats& stats, const std::string& title) {
  std::string out;
  if (!title.empty()) out += title + "\n";
  append_format(out, "epochs in %d, with solution %d", stats.epochs_in, stats.epochs_with_solution);
  if (stats.has_truth) append_format(out, ", with truth %d", stats.epochs_with_truth);
  out += "\n";
  append_format(out, "%-8s %6s %7s %7s %6s %8s %8s %8s %8s %8s\n", "status", "epochs", "%solved", "%in", "truth",
                "hrms(m)", "vrms(m)", "3drms(m)", "3dmax(m)", "3dp95(m)");
  for (std::size_t k = 0; k < kNumStatusClasses; ++k) {
    const StatusStats& st = stats.by_class[k];
    if (st.epochs == 0 && k > static_cast<std::size_t>(StatusClass::Float)) continue;
    append_format(out, "%-8s %6d %7.1f %7.1f", status_class_name(static_cast<StatusClass>(k)), st.epochs,
                  100.0 * st.fraction_of_solved, 100.0 * st.fraction_of_epochs_in);
    append_error_columns(out, st.error);
    out += "\n";
  }
  append_format(out, "%-8s %6d %7.1f %7.1f", "all", stats.epochs_with_solution,
                stats.epochs_with_solution > 0 ? 100.0 : 0.0,
                100.0 * ratio(stats.epochs_with_solution, stats.epochs_in));
  append_error_columns(out, stats.overall);
  out += "\n";
  if (stats.has_truth) {
    append_format(out, "wrong fixes (3D error > %.3f m): %d of %d fixed\n", stats.wrong_fix_threshold_m,
                  stats.wrong_fixes, stats.fixed().epochs);
  }
  if (stats.time_to_first_fix_s) {
    append_format(out, "time to first fix: %.1f s\n", *stats.time_to_first_fix_s);
  } else {
    out += "time to first fix: never fixed\n";
  }
  return out;
}

std::string format_agreement(const Agreement& agreement, const std::string& name_a, const std::string& name_b) {
  std::string out;
  append_format(out, "solutions: %s %d, %s %d, both %d\n", name_a.c_str(), agreement.epochs_a, name_b.c_str(),
                agreement.epochs_b, agreement.matched);
  append_format(out, "fixed in both %d, only %s %d, only %s %d\n", agreement.both_fixed, name_a.c_str(),
                agreement.only_a_fixed, name_b.c_str(), agreement.only_b_fixed);
  if (agreement.both_fixed > 0) {
    append_format(out, "distance where both fixed: max %.4f m, RMS %.4f m\n", agreement.max_distance_fixed_m,
                  agreement.rms_distance_fixed_m);
  }
  append_format(out, "distance where both solved: max %.4f m\n", agreement.max_distance_matched_m);
  return out;
}

std::string format_key_values(const SolutionStats& stats, const std::optional<Agreement>& agreement) {
  std::string out;
  append_format(out, "epochs_in=%d solved=%d fixed=%d float=%d fixed_pct=%.1f float_pct=%.1f", stats.epochs_in,
                stats.epochs_with_solution, stats.fixed().epochs, stats.floating().epochs,
                100.0 * stats.fixed().fraction_of_epochs_in, 100.0 * stats.floating().fraction_of_epochs_in);
  if (stats.has_truth && stats.overall.count > 0) {
    append_format(out, " rmse_3d_m=%.4f wrong_fixes=%d", stats.overall.rmse_3d_m, stats.wrong_fixes);
  } else {
    out += " rmse_3d_m=- wrong_fixes=-";
  }
  if (stats.time_to_first_fix_s) {
    append_format(out, " ttff_s=%.1f", *stats.time_to_first_fix_s);
  } else {
    out += " ttff_s=-";
  }
  if (agreement) {
    append_format(out, " both_fixed=%d", agreement->both_fixed);
    if (agreement->both_fixed > 0) {
      append_format(out, " max_fixed_dist_m=%.4f rms_fixed_dist_m=%.4f", agreement->max_distance_fixed_m,
                    agreement->rms_distance_fixed_m);
    } else {
      out += " max_fixed_dist_m=- rms_fixed_dist_m=-";
    }
  }
  return out;
}

Result<std::string> evaluate_files(const std::string& solution_path, const std::string& truth_spec,
                                   const EvalOptions& options, const std::string& reference_path) {
  auto solutions = io::read_pos_file(solution_path);
  if (!solutions) return solutions.error();
  std::optional<Truth> truth;
  if (!truth_spec.empty()) {
    auto parsed = parse_truth_spec(truth_spec);
    if (!parsed) return parsed.error();
    truth = std::move(parsed.value());
  }
  auto stats = evaluate(*solutions, truth ? &*truth : nullptr, options);
  if (!stats) return Error{stats.error().message, solution_path, 0};
  std::string report = format_stats(*stats, solution_path);
  if (!reference_path.empty()) {
    auto reference = io::read_pos_file(reference_path);
    if (!reference) return reference.error();
    auto agreement = compare(*solutions, *reference, options.time_tolerance_s);
    if (!agreement) return agreement.error();
    report += "compared with " + reference_path + "\n";
    report += format_agreement(*agreement, "solution", "reference");
  }
  return report;
}

}  // namespace canyon::eval
