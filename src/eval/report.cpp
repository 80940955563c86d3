// Several solutions scored side by side, as text, Markdown and JSON (see report.hpp).

#include "canyon/eval/report.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace canyon::eval {
namespace {

template <typename... Args>
std::string format(const char* fmt, Args... args) {
  char buffer[256];
  const int n = std::snprintf(buffer, sizeof buffer, fmt, args...);
  return std::string(buffer, n < 0 ? 0 : std::min<std::size_t>(static_cast<std::size_t>(n), sizeof buffer - 1));
}

std::string calendar_text(const core::GpsTime& t) {
  return core::format_calendar(core::gps_to_calendar(t.normalized()), 3);
}

/// "2021-03-19 12:00:00.000 - 2021-03-19 12:00:59.000 GPST"
std::string span_text(const core::GpsTime& first, const core::GpsTime& last) {
  return calendar_text(first) + " - " + calendar_text(last) + " GPST";
}

/// Number of distinct times in `times_s` (seconds from any common reference), closer than `tolerance_s` being one.
int count_distinct(std::vector<double> times_s, double tolerance_s) {
  std::sort(times_s.begin(), times_s.end());
  int count = 0;
  double last_s = 0.0;
  for (std::size_t i = 0; i < times_s.size(); ++i) {
    if (i == 0 || times_s[i] - last_s > tolerance_s) {
      ++count;
      last_s = times_s[i];
    }
  }
  return count;
}

double median_interval_s(std::vector<double> times_s) {
  if (times_s.size() < 2) return 0.0;
  std::sort(times_s.begin(), times_s.end());
  std::vector<double> intervals_s;
  intervals_s.reserve(times_s.size() - 1);
  for (std::size_t i = 1; i < times_s.size(); ++i) intervals_s.push_back(times_s[i] - times_s[i - 1]);
  std::nth_element(intervals_s.begin(), intervals_s.begin() + static_cast<std::ptrdiff_t>(intervals_s.size() / 2),
                   intervals_s.end());
  return intervals_s[intervals_s.size() / 2];
}

bool has_solution(const core::Solution& s) {
  return s.status != core::SolutionStatus::None;
}

/// Solved records sorted by time.
std::vector<core::Solution> solved_by_time(std::vector<core::Solution> solutions) {
  solutions.erase(std::remove_if(solutions.begin(), solutions.end(), [](const auto& s) { return !has_solution(s); }),
                  solutions.end());
  std::sort(solutions.begin(), solutions.end(), [](const auto& a, const auto& b) { return a.time < b.time; });
  return solutions;
}

/// Warns when a trajectory truth is sampled faster than the solutions: counting its epochs then overstates the
/// rover epochs.
std::optional<std::string> denser_truth_warning(const Truth& truth, const std::vector<SolutionReport>& reports) {
  if (truth.is_constant() || truth.samples().size() < 2) return std::nullopt;
  const core::GpsTime t0 = truth.samples().front().time;
  std::vector<double> truth_s;
  truth_s.reserve(truth.samples().size());
  for (const TruthSample& s : truth.samples()) truth_s.push_back(s.time - t0);
  const double truth_interval_s = median_interval_s(truth_s);
  double solution_interval_s = 0.0;
  for (const SolutionReport& r : reports) {
    std::vector<double> times_s;
    times_s.reserve(r.solutions.size());
    for (const core::Solution& s : r.solutions) times_s.push_back(s.time - t0);
    const double interval_s = median_interval_s(times_s);
    if (interval_s > 0.0 && (solution_interval_s == 0.0 || interval_s < solution_interval_s)) {
      solution_interval_s = interval_s;
    }
  }
  if (truth_interval_s <= 0.0 || truth_interval_s >= 0.75 * solution_interval_s) return std::nullopt;
  return format(
      "the truth is sampled every %.3g s, the solutions every %.3g s: its epochs overstate the rover "
      "epochs; give --epochs N or --rover OBS",
      truth_interval_s, solution_interval_s);
}

// ---- The table --------------------------------------------------------------------------------------------------

struct TableRow {
  std::string name;
  std::vector<std::string> values;  ///< one per solution; empty for a section title
};

constexpr std::array<StatusClass, kNumStatusClasses> kClassOrder = {
    StatusClass::Fixed, StatusClass::Float, StatusClass::Single, StatusClass::VioFillIn, StatusClass::Other};

/// Names in the table and the JSON.
const char* class_label(StatusClass c) {
  switch (c) {
    case StatusClass::Fixed: return "fixed";
    case StatusClass::Float: return "float";
    case StatusClass::Single: return "single";
    case StatusClass::VioFillIn: return "fill-in";
    case StatusClass::Other: return "other";
  }
  return "?";
}
const char* class_key(StatusClass c) {
  return c == StatusClass::VioFillIn ? "fill_in" : class_label(c);
}

std::string metres(double value_m) {
  return format("%.3f", value_m);
}

std::string count_and_percent(int count, int total) {
  return format("%d (%.2f)", count, total > 0 ? 100.0 * count / total : 0.0);
}

/// Rows of one figure over every solution.
template <typename Value>
TableRow row(const std::string& name, const EvaluationReport& report, Value value) {
  TableRow r{name, {}};
  for (const SolutionReport& s : report.solutions) r.values.push_back(value(s));
  return r;
}

bool any_class_errors(const EvaluationReport& report, const StatusClass* c) {
  return std::any_of(report.solutions.begin(), report.solutions.end(), [&](const SolutionReport& s) {
    return (c == nullptr ? s.stats.overall : s.stats.of(*c).error).count > 0;
  });
}

/// The APE rows of one status class (nullptr: all epochs).
void append_ape_rows(std::vector<TableRow>& rows, const EvaluationReport& report, const StatusClass* c) {
  if (!any_class_errors(report, c)) return;
  const std::string of = c == nullptr ? "all epochs" : class_label(*c);
  const auto errors = [c](const SolutionReport& s) -> const ErrorStats& {
    return c == nullptr ? s.stats.overall : s.stats.of(*c).error;
  };
  struct Figure {
    const char* name;
    double ErrorDistribution::*member;
  };
  static constexpr std::array<Figure, 6> kFigures = {{{"RMSE", &ErrorDistribution::rmse_m},
                                                      {"mean", &ErrorDistribution::mean_m},
                                                      {"median", &ErrorDistribution::median_m},
                                                      {"std", &ErrorDistribution::std_m},
                                                      {"max", &ErrorDistribution::max_m},
                                                      {"p95", &ErrorDistribution::p95_m}}};
  for (const bool horizontal : {false, true}) {
    rows.push_back({std::string("APE ") + (horizontal ? "horizontal" : "3D") + ", " + of + " (m)", {}});
    rows.push_back(row("  epochs", report, [&](const SolutionReport& s) { return std::to_string(errors(s).count); }));
    for (const Figure& f : kFigures) {
      rows.push_back(row(std::string("  ") + f.name, report, [&](const SolutionReport& s) -> std::string {
        const ErrorStats& e = errors(s);
        if (e.count == 0) return "-";
        return metres((horizontal ? e.ape_horizontal : e.ape_3d).*f.member);
      }));
    }
  }
}

/// Fixed epochs within the wrong-fix threshold of the truth: the correct-fix rate's numerator (over all epochs).
int correct_fixes(const SolutionStats& st) {
  return st.fixed().error.count - st.wrong_fixes;
}

std::vector<TableRow> table_rows(const EvaluationReport& report) {
  std::vector<TableRow> rows;
  const int epochs = report.epochs.epochs;
  rows.push_back(row("epochs", report, [&](const SolutionReport&) { return std::to_string(epochs); }));
  rows.push_back(row("solved (availability %)", report,
                     [&](const SolutionReport& s) { return count_and_percent(s.stats.epochs_with_solution, epochs); }));
  for (const StatusClass c : kClassOrder) {
    const bool present = std::any_of(report.solutions.begin(), report.solutions.end(),
                                     [c](const SolutionReport& s) { return s.stats.of(c).epochs > 0; });
    if (c == StatusClass::Other && !present) continue;
    rows.push_back(row(std::string(class_label(c)) + " (%)", report,
                       [&](const SolutionReport& s) { return count_and_percent(s.stats.of(c).epochs, epochs); }));
  }
  rows.push_back(row(format("wrong fixes > %.2f m (%% of fixed)", report.wrong_fix_threshold_m), report,
                     [](const SolutionReport& s) -> std::string {
                       if (!s.wrong_fix_rate) return std::to_string(s.stats.wrong_fixes);
                       return format("%d (%.2f)", s.stats.wrong_fixes, 100.0 * *s.wrong_fix_rate);
                     }));
  rows.push_back(row(format("correct fixes <= %.2f m (%%)", report.wrong_fix_threshold_m), report,
                     [&](const SolutionReport& s) { return count_and_percent(correct_fixes(s.stats), epochs); }));
  rows.push_back(row("horizontal error > 3 sigma (%)", report, [](const SolutionReport& s) {
    return count_and_percent(s.stats.beyond_3_sigma_horizontal, s.stats.epochs_with_covariance);
  }));
  rows.push_back(row("horizontal error > HPL (%)", report, [](const SolutionReport& s) {
    return count_and_percent(s.stats.beyond_protection_level, s.stats.epochs_with_covariance);
  }));
  rows.push_back(row("epochs without truth", report,
                     [](const SolutionReport& s) { return std::to_string(s.stats.epochs_without_truth); }));
  rows.push_back(row("time to first fix (s)", report, [](const SolutionReport& s) -> std::string {
    return s.stats.time_to_first_fix_s ? format("%.1f", *s.stats.time_to_first_fix_s) : "never";
  }));
  append_ape_rows(rows, report, nullptr);
  for (const StatusClass c : kClassOrder) append_ape_rows(rows, report, &c);
  return rows;
}

std::string truth_line(const EvaluationReport& report) {
  if (report.truth_is_trajectory) {
    return format("truth: %s (trajectory, %d samples)", report.truth_source.c_str(), report.truth_samples);
  }
  return "truth: " + report.truth_source + " (static)";
}

std::string epochs_line(const EvaluationReport& report) {
  const char* how = "";
  switch (report.epochs.source) {
    case EpochSource::Given: how = "given"; break;
    case EpochSource::RoverFile: how = "epochs of the rover file"; break;
    case EpochSource::TruthEpochs: how = "truth epochs within the solutions' span and the solutions' epochs"; break;
    case EpochSource::SolutionEpochs: how = "union of the solutions' epochs"; break;
  }
  return format("rover epochs: %d (%s)", report.epochs.epochs, how);
}

// ---- JSON -------------------------------------------------------------------------------------------------------

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += format("\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string json_number(double value) {
  if (!std::isfinite(value)) return "null";
  return format("%.10g", value);
}

std::string json_optional(const std::optional<double>& value) {
  return value ? json_number(*value) : "null";
}

std::string json_distribution(const ErrorDistribution& d) {
  return "{\"rmse_m\": " + json_number(d.rmse_m) + ", \"mean_m\": " + json_number(d.mean_m) +
         ", \"median_m\": " + json_number(d.median_m) + ", \"std_m\": " + json_number(d.std_m) +
         ", \"max_m\": " + json_number(d.max_m) + ", \"p95_m\": " + json_number(d.p95_m) + "}";
}

std::string json_errors(const ErrorStats& e) {
  if (e.count == 0) return "{\"epochs\": 0, \"3d\": null, \"horizontal\": null, \"vertical_rmse_m\": null}";
  return "{\"epochs\": " + std::to_string(e.count) + ", \"3d\": " + json_distribution(e.ape_3d) +
         ", \"horizontal\": " + json_distribution(e.ape_horizontal) +
         ", \"vertical_rmse_m\": " + json_number(e.vertical_rmse_m) + "}";
}

std::string json_solution(const SolutionReport& r, int epochs) {
  const SolutionStats& st = r.stats;
  const auto rate = [epochs](int count) { return json_number(epochs > 0 ? double(count) / epochs : 0.0); };
  std::string out = "    {\n";
  out += "      \"label\": " + json_string(r.label) + ",\n";
  out += "      \"file\": " + json_string(r.path) + ",\n";
  out += "      \"epochs\": " + std::to_string(epochs) + ",\n";
  out += "      \"solved\": " + std::to_string(st.epochs_with_solution) + ",\n";
  out += "      \"availability\": " + rate(st.epochs_with_solution) + ",\n";
  out += "      \"status\": {";
  for (std::size_t k = 0; k < kClassOrder.size(); ++k) {
    const StatusClass c = kClassOrder[k];
    out += std::string(k == 0 ? "" : ", ") + "\"" + class_key(c) +
           "\": {\"epochs\": " + std::to_string(st.of(c).epochs) + ", \"rate\": " + rate(st.of(c).epochs) + "}";
  }
  out += "},\n";
  out += "      \"wrong_fixes\": " + std::to_string(st.wrong_fixes) + ",\n";
  out += "      \"wrong_fix_rate\": " + json_optional(r.wrong_fix_rate) + ",\n";
  out += "      \"correct_fixes\": " + std::to_string(correct_fixes(st)) + ",\n";
  out += "      \"correct_fix_rate\": " + rate(correct_fixes(st)) + ",\n";
  out += "      \"beyond_3_sigma_horizontal\": " + std::to_string(st.beyond_3_sigma_horizontal) + ",\n";
  out += "      \"epochs_with_covariance\": " + std::to_string(st.epochs_with_covariance) + ",\n";
  out += "      \"beyond_protection_level\": " + std::to_string(st.beyond_protection_level) + ",\n";
  out += "      \"epochs_with_truth\": " + std::to_string(st.epochs_with_truth) + ",\n";
  out += "      \"epochs_without_truth\": " + std::to_string(st.epochs_without_truth) + ",\n";
  out += "      \"time_to_first_fix_s\": " + json_optional(st.time_to_first_fix_s) + ",\n";
  out += "      \"ape\": {\n        \"all\": " + json_errors(st.overall);
  for (const StatusClass c : kClassOrder) {
    out += ",\n        \"" + std::string(class_key(c)) + "\": " + json_errors(st.of(c).error);
  }
  out += "\n      }\n    }";
  return out;
}

}  // namespace

const char* epoch_source_name(EpochSource source) {
  switch (source) {
    case EpochSource::Given: return "given";
    case EpochSource::RoverFile: return "rover-file";
    case EpochSource::TruthEpochs: return "truth+solutions";
    case EpochSource::SolutionEpochs: return "solutions";
  }
  return "?";
}

EpochCount count_epochs(const Truth& truth, const std::vector<std::vector<core::Solution>>& solution_sets,
                        double time_tolerance_s) {
  std::optional<core::GpsTime> first;
  std::optional<core::GpsTime> last;
  for (const auto& set : solution_sets) {
    for (const core::Solution& s : set) {
      if (!first || s.time < *first) first = s.time;
      if (!last || *last < s.time) last = s.time;
    }
  }
  EpochCount count;
  if (!first) return count;
  std::vector<double> times_s;
  for (const auto& set : solution_sets) {
    for (const core::Solution& s : set) times_s.push_back(s.time - *first);
  }
  count.source = EpochSource::SolutionEpochs;
  if (!truth.is_constant()) {
    count.source = EpochSource::TruthEpochs;
    const double span_s = *last - *first;
    for (const TruthSample& t : truth.samples()) {
      const double dt_s = t.time - *first;
      if (dt_s >= -time_tolerance_s && dt_s <= span_s + time_tolerance_s) times_s.push_back(dt_s);
    }
  }
  count.epochs = count_distinct(std::move(times_s), time_tolerance_s);
  count.first = *first;
  return count;
}

Result<EvaluationReport> evaluate_report(std::vector<SolutionInput> inputs, const Truth& truth,
                                         const std::string& truth_source, const ReportOptions& options) {
  if (inputs.empty()) return Error{"no solution to evaluate"};
  EvaluationReport report;
  report.truth_source = truth_source;
  report.truth_is_trajectory = !truth.is_constant();
  report.truth_samples = static_cast<int>(truth.samples().size());
  report.wrong_fix_threshold_m = options.wrong_fix_threshold_m;
  if (options.epochs) {
    report.epochs = *options.epochs;
  } else {
    std::vector<std::vector<core::Solution>> sets;
    sets.reserve(inputs.size());
    for (SolutionInput& in : inputs) sets.push_back(solved_by_time(in.solutions));
    report.epochs = count_epochs(truth, sets, options.time_tolerance_s);
  }
  EvalOptions eval_options;
  eval_options.wrong_fix_threshold_m = options.wrong_fix_threshold_m;
  eval_options.time_tolerance_s = options.time_tolerance_s;
  eval_options.epochs_in = report.epochs.epochs;
  eval_options.first_epoch = report.epochs.first;
  for (SolutionInput& in : inputs) {
    auto stats = evaluate(in.solutions, &truth, eval_options);
    if (!stats) return Error{stats.error().message, in.path};
    SolutionReport r{in.label, in.path, solved_by_time(std::move(in.solutions)), *stats, std::nullopt};
    const SolutionStats& st = r.stats;
    if (st.epochs_with_solution > report.epochs.epochs) {
      return Error{format("%d solved epochs, but only %d rover epochs (%s)", st.epochs_with_solution,
                          report.epochs.epochs, epoch_source_name(report.epochs.source)),
                   in.path};
    }
    if (st.epochs_with_solution == 0) {
      report.warnings.push_back(in.path + ": no solutions");
    } else if (st.epochs_with_truth == 0) {
      const auto& s = r.solutions;
      std::string truth_span = "static";
      if (!truth.is_constant()) truth_span = span_text(truth.samples().front().time, truth.samples().back().time);
      std::string message = "no solved epoch has truth: the solutions span ";
      message.append(span_text(s.front().time, s.back().time)).append(", the truth (").append(truth_source);
      message.append(") ").append(truth_span);
      return Error{std::move(message), in.path};
    } else if (st.epochs_without_truth > 0) {
      report.warnings.push_back(format("%s: %d of %d solved epochs have no truth (outside its span or in its gaps)",
                                       in.path.c_str(), st.epochs_without_truth, st.epochs_with_solution));
    }
    const int fixed_with_truth = st.fixed().error.count;
    if (fixed_with_truth > 0) r.wrong_fix_rate = static_cast<double>(st.wrong_fixes) / fixed_with_truth;
    report.solutions.push_back(std::move(r));
  }
  if (report.epochs.source == EpochSource::TruthEpochs) {
    if (auto warning = denser_truth_warning(truth, report.solutions)) report.warnings.push_back(*warning);
  }
  return report;
}

std::string format_text_table(const EvaluationReport& report) {
  const std::vector<TableRow> rows = table_rows(report);
  std::size_t name_width = 0;
  std::vector<std::size_t> widths;
  for (const SolutionReport& s : report.solutions) widths.push_back(s.label.size());
  for (const TableRow& r : rows) {
    name_width = std::max(name_width, r.name.size());
    for (std::size_t k = 0; k < r.values.size(); ++k) widths[k] = std::max(widths[k], r.values[k].size());
  }
  const auto line = [&](const std::string& name, const std::vector<std::string>& values) {
    std::string out = name + std::string(name_width - name.size(), ' ');
    for (std::size_t k = 0; k < values.size(); ++k) {
      out += k == 0 ? "  " : " : ";
      out += std::string(widths[k] - values[k].size(), ' ') + values[k];
    }
    return out + "\n";
  };
  std::string out = truth_line(report) + "\n" + epochs_line(report) + "\n";
  std::vector<std::string> labels;
  for (const SolutionReport& s : report.solutions) labels.push_back(s.label);
  out += line("", labels);
  for (const TableRow& r : rows) out += r.values.empty() ? r.name + "\n" : line(r.name, r.values);
  return out;
}

std::string format_markdown(const EvaluationReport& report) {
  std::string out = "# canyon evaluate\n\n";
  out += truth_line(report) + "  \n" + epochs_line(report) + "\n\n";
  for (const SolutionReport& s : report.solutions) out += "- " + s.label + ": `" + s.path + "`\n";
  out += "\n| |";
  std::string rule = "\n|---|";
  for (const SolutionReport& s : report.solutions) {
    out += " " + s.label + " |";
    rule += "---:|";
  }
  out += rule + "\n";
  for (const TableRow& r : table_rows(report)) {
    if (r.values.empty()) {
      out += "| **" + r.name + "** |";
      for (std::size_t k = 0; k < report.solutions.size(); ++k) out += " |";
      out += "\n";
      continue;
    }
    out += "| " + r.name + " |";
    for (const std::string& v : r.values) out += " " + v + " |";
    out += "\n";
  }
  if (!report.warnings.empty()) {
    out += "\nWarnings:\n\n";
    for (const std::string& w : report.warnings) out += "- " + w + "\n";
  }
  return out;
}

std::string format_json(const EvaluationReport& report) {
  std::string out = "{\n";
  out += "  \"format\": \"canyon-evaluate/1\",\n";
  out += "  \"truth\": {\"source\": " + json_string(report.truth_source) + ", \"kind\": \"" +
         (report.truth_is_trajectory ? "trajectory" : "static") +
         "\", \"samples\": " + std::to_string(report.truth_samples) + "},\n";
  out += "  \"epochs\": {\"count\": " + std::to_string(report.epochs.epochs) + ", \"source\": \"" +
         epoch_source_name(report.epochs.source) + "\"},\n";
  out += "  \"wrong_fix_threshold_m\": " + json_number(report.wrong_fix_threshold_m) + ",\n";
  out += "  \"solutions\": [\n";
  for (std::size_t k = 0; k < report.solutions.size(); ++k) {
    out += json_solution(report.solutions[k], report.epochs.epochs) + (k + 1 < report.solutions.size() ? ",\n" : "\n");
  }
  out += "  ],\n  \"warnings\": [";
  for (std::size_t k = 0; k < report.warnings.size(); ++k)
    out += (k == 0 ? "" : ", ") + json_string(report.warnings[k]);
  out += "]\n}\n";
  return out;
}

}  // namespace canyon::eval
