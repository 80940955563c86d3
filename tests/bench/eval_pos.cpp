// bench_eval_pos: scores a .pos solution file (canyon's or RTKLIB's) against a truth and, optionally, against a
// second solution file, through canyon::eval (the same code `canyon evaluate` and the eval tests use).
//
// Usage: bench_eval_pos SOL.pos [--truth SPEC] [--ref OTHER.pos] [--epochs-in N] [--threshold-m M]
//                       [--tolerance-s S] [--kv]
//   SPEC: ecef:X,Y,Z | llh:LAT,LON,H | truth file (Spirent PVA csv, canyon truth csv, week-tow-xyz .pos)
//   --kv  one line of key=value pairs for scripts (tests/bench/rtk_vs_rtklib.sh) instead of the text report
// Exit status: 0 success, 1 bad input (message names the file and line), 2 bad command line.

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

#include "canyon/eval/metrics.hpp"
#include "canyon/io/pos_file.hpp"

namespace {

int usage(const char* message) {
  std::fprintf(stderr,
               "bench_eval_pos: %s\nusage: bench_eval_pos SOL.pos [--truth SPEC] [--ref OTHER.pos] [--epochs-in N] "
               "[--threshold-m M] [--tolerance-s S] [--kv]\n",
               message);
  return 2;
}

int fail(const canyon::Error& error) {
  std::fprintf(stderr, "bench_eval_pos: %s\n", error.to_string().c_str());
  return 1;
}

std::optional<double> to_number(const char* text) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0') return std::nullopt;
  return value;
}

struct Arguments {
  std::string solution_path;
  std::string truth_spec;
  std::string reference_path;
  canyon::eval::EvalOptions options;
  bool key_values = false;
};

/// Parses the command line; returns the message of the first problem, or empty.
std::string parse(int argc, char** argv, Arguments& args) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--kv") {
      args.key_values = true;
    } else if (arg == "--truth" && has_value) {
      args.truth_spec = argv[++i];
    } else if (arg == "--ref" && has_value) {
      args.reference_path = argv[++i];
    } else if ((arg == "--epochs-in" || arg == "--threshold-m" || arg == "--tolerance-s") && has_value) {
      const auto value = to_number(argv[++i]);
      if (!value) return std::string("bad number for ") + std::string(arg);
      if (arg == "--epochs-in") args.options.epochs_in = static_cast<int>(*value);
      if (arg == "--threshold-m") args.options.wrong_fix_threshold_m = *value;
      if (arg == "--tolerance-s") args.options.time_tolerance_s = *value;
    } else if (!arg.empty() && arg.front() != '-' && args.solution_path.empty()) {
      args.solution_path = arg;
    } else {
      return "unexpected argument '" + std::string(arg) + "'";
    }
  }
  if (args.solution_path.empty()) return "no solution file given";
  return {};
}

int print_key_values(const Arguments& args) {
  auto solutions = canyon::io::read_pos_file(args.solution_path);
  if (!solutions) return fail(solutions.error());
  std::optional<canyon::eval::Truth> truth;
  if (!args.truth_spec.empty()) {
    auto parsed = canyon::eval::parse_truth_spec(args.truth_spec);
    if (!parsed) return fail(parsed.error());
    truth = std::move(parsed.value());
  }
  auto stats = canyon::eval::evaluate(*solutions, truth ? &*truth : nullptr, args.options);
  if (!stats) return fail(canyon::Error{stats.error().message, args.solution_path});
  std::optional<canyon::eval::Agreement> agreement;
  if (!args.reference_path.empty()) {
    auto reference = canyon::io::read_pos_file(args.reference_path);
    if (!reference) return fail(reference.error());
    auto compared = canyon::eval::compare(*solutions, *reference, args.options.time_tolerance_s);
    if (!compared) return fail(compared.error());
    agreement = *compared;
  }
  std::printf("%s\n", canyon::eval::format_key_values(*stats, agreement).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Arguments args;
  if (const std::string problem = parse(argc, argv, args); !problem.empty()) return usage(problem.c_str());
  if (args.key_values) return print_key_values(args);
  auto report = canyon::eval::evaluate_files(args.solution_path, args.truth_spec, args.options, args.reference_path);
  if (!report) return fail(report.error());
  std::fputs(report->c_str(), stdout);
  return 0;
}
