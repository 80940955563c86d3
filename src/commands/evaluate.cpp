// `canyon evaluate` (see evaluate.hpp).

#include "canyon/commands/evaluate.hpp"

#include <algorithm>
#include <filesystem>
#include <set>

#include "canyon/eval/city_map.hpp"
#include "canyon/eval/map_tracks.hpp"
#include "canyon/eval/plots.hpp"
#include "canyon/eval/report.hpp"
#include "canyon/io/pos_file.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/io/text_file_writer.hpp"

namespace canyon::commands {
namespace {

namespace fs = std::filesystem;

/// Epochs of a rover observation file: distinct epoch times (flag 6 records repeat a time), and the first one.
Result<eval::EpochCount> count_rover_epochs(const std::string& path, std::vector<std::string>& warnings) {
  auto reader = io::RinexObsReader::open(path);
  if (!reader) return reader.error();
  eval::EpochCount count;
  count.source = eval::EpochSource::RoverFile;
  std::optional<core::GpsTime> last;
  while (true) {
    auto epoch = reader->next();
    if (!epoch) return epoch.error();
    if (!*epoch) break;
    const core::GpsTime t = (*epoch)->time;
    if (last && std::abs(t - *last) < 1e-6) continue;
    if (!count.first) count.first = t;
    last = t;
    ++count.epochs;
  }
  for (const std::string& w : reader->warnings()) warnings.push_back(w + " (rover epochs counted without it)");
  if (count.epochs == 0) return Error{"no observation epochs to count", path, 0};
  return count;
}

struct OutputPaths {
  std::string markdown;
  std::string json;
  std::string trajectory_svg;
  std::string ape_svg;
};

OutputPaths output_paths(const EvaluateConfig& c) {
  OutputPaths out{c.markdown, c.json, c.trajectory_svg, c.ape_svg};
  const bool any_file = !(c.markdown.empty() && c.json.empty() && c.trajectory_svg.empty() && c.ape_svg.empty() &&
                          c.kml.empty() && c.gpx.empty());
  std::string dir = c.out_dir;
  if (dir.empty() && !any_file) dir = (fs::path(c.solutions.front()).parent_path() / "evaluation").string();
  if (dir.empty()) return out;
  const fs::path d(dir);
  if (out.markdown.empty()) out.markdown = (d / "evaluation.md").string();
  if (out.json.empty()) out.json = (d / "evaluation.json").string();
  if (out.trajectory_svg.empty()) out.trajectory_svg = (d / "trajectory.svg").string();
  if (out.ape_svg.empty()) out.ape_svg = (d / "ape.svg").string();
  return out;
}

/// The KML and GPX tracks of the evaluated solutions with the truth; an error lists what was written before it.
Status write_map_tracks(const EvaluateConfig& config, const eval::EvaluationReport& report, const eval::Truth& truth,
                        std::vector<std::string>& written) {
  if (config.kml.empty() && config.gpx.empty()) return Ok{};
  eval::MapTracks tracks;
  for (const eval::SolutionReport& s : report.solutions) tracks.tracks.push_back({s.label, s.solutions});
  tracks.truth = truth.samples();
  const auto attempt = [&](const std::string& path, Status (*writer)(const std::string&, const eval::MapTracks&)) {
    if (path.empty()) return Status{Ok{}};
    if (Status s = writer(path, tracks); !s) {
      std::string kept;
      for (const std::string& w : written) kept += (kept.empty() ? "" : ", ") + w;
      Error e = s.error();
      e.message += kept.empty() ? " (nothing else was written)" : " (written before it and kept: " + kept + ")";
      return Status{e};
    }
    written.push_back(path);
    return Status{Ok{}};
  };
  if (Status s = attempt(config.kml, eval::write_kml); !s) return s;
  return attempt(config.gpx, eval::write_gpx);
}

}  // namespace

std::string EvaluateConfig::validate() const {
  if (truth.empty()) return "--truth is required";
  if (solutions.empty()) return "at least one --solution is required";
  if (!labels.empty() && labels.size() != solutions.size()) {
    return std::to_string(labels.size()) + " labels for " + std::to_string(solutions.size()) +
           " solutions: give a --label for every --solution, or none";
  }
  if (std::set<std::string>(labels.begin(), labels.end()).size() != labels.size()) return "labels must differ";
  if (epochs && *epochs <= 0) return "--epochs must be positive";
  if (epochs && !rover_obs.empty()) return "give --epochs or --rover, not both";
  if (!(wrong_fix_threshold_m > 0.0)) return "the wrong-fix threshold must be positive";
  if (!(time_tolerance_s > 0.0)) return "the time tolerance must be positive";
  return {};
}

std::vector<std::string> solution_labels(const EvaluateConfig& config) {
  if (!config.labels.empty()) return config.labels;
  std::vector<std::string> labels;
  for (const std::string& path : config.solutions) labels.push_back(fs::path(path).stem().string());
  if (std::set<std::string>(labels.begin(), labels.end()).size() != labels.size()) return config.solutions;
  return labels;
}

Result<EvaluateSummary> run_evaluate(const EvaluateConfig& config) {
  if (const std::string broken = config.validate(); !broken.empty()) return Error{broken};
  EvaluateSummary summary;
  auto truth = eval::parse_truth_spec(config.truth);
  if (!truth) return truth.error();
  const std::vector<std::string> labels = solution_labels(config);
  std::vector<eval::SolutionInput> inputs;
  for (std::size_t k = 0; k < config.solutions.size(); ++k) {
    auto solutions = io::read_pos_file(config.solutions[k]);
    if (!solutions) return solutions.error();
    inputs.push_back({labels[k], config.solutions[k], std::move(*solutions)});
  }
  std::optional<eval::CityMap> city;
  if (!config.city.empty()) {
    auto read = eval::read_city_geojson(config.city);
    if (!read) return read.error();
    city = std::move(*read);
  }
  eval::ReportOptions options;
  options.wrong_fix_threshold_m = config.wrong_fix_threshold_m;
  options.time_tolerance_s = config.time_tolerance_s;
  if (config.epochs) {
    options.epochs = eval::EpochCount{*config.epochs, eval::EpochSource::Given, std::nullopt};
  } else if (!config.rover_obs.empty()) {
    auto count = count_rover_epochs(config.rover_obs, summary.warnings);
    if (!count) return count.error();
    options.epochs = *count;
  }
  auto report = eval::evaluate_report(std::move(inputs), *truth, config.truth, options);
  if (!report) return report.error();
  summary.warnings.insert(summary.warnings.end(), report->warnings.begin(), report->warnings.end());
  summary.table = eval::format_text_table(*report);

  const OutputPaths out = output_paths(config);
  const eval::CityMap* city_map = city ? &*city : nullptr;
  const auto write = [&summary](const std::string& path, const auto& produce) -> Status {
    if (path.empty()) return Ok{};
    if (Status s = produce(path); !s) return s;
    summary.written.push_back(path);
    return Ok{};
  };
  if (Status s = write(out.markdown,
                       [&](const std::string& p) {
                         return io::write_text_file(p, eval::format_markdown(*report), "Markdown file");
                       });
      !s) {
    return s.error();
  }
  if (Status s =
          write(out.json,
                [&](const std::string& p) { return io::write_text_file(p, eval::format_json(*report), "JSON file"); });
      !s) {
    return s.error();
  }
  if (Status s = write(out.trajectory_svg,
                       [&](const std::string& p) { return eval::trajectory_plot(*report, *truth, city_map).write(p); });
      !s) {
    return s.error();
  }
  if (Status s = write(out.ape_svg, [&](const std::string& p) { return eval::ape_plot(*report, *truth).write(p); });
      !s) {
    return s.error();
  }
  if (Status s = write_map_tracks(config, *report, *truth, summary.written); !s) return s.error();
  return summary;
}

}  // namespace canyon::commands
