#include "canyon/eval/truth.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string_view>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/io/pos_file.hpp"
#include "canyon/io/text_reader.hpp"

namespace canyon::eval {
namespace {

std::vector<std::string_view> split_commas(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(
        io::trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

std::optional<std::size_t> find_column(const std::vector<std::string_view>& header, std::string_view name) {
  const auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end()) return std::nullopt;
  return static_cast<std::size_t>(it - header.begin());
}

/// Column indices of week, tow, x, y, z (and optionally the GPS cycle) in a CSV header.
struct CsvLayout {
  std::optional<std::size_t> cycle;
  std::size_t week = 0;
  std::size_t tow = 0;
  std::array<std::size_t, 3> xyz{};
};

Result<Truth> read_csv_with_layout(io::TextReader& reader, const CsvLayout& layout, TruthOptions options) {
  std::vector<TruthSample> samples;
  std::size_t needed = std::max({layout.week, layout.tow, layout.xyz[0], layout.xyz[1], layout.xyz[2]});
  if (layout.cycle) needed = std::max(needed, *layout.cycle);
  while (auto line = reader.next_line()) {
    if (io::trim(*line).empty()) continue;
    const auto fields = split_commas(*line);
    if (fields.size() <= needed) return reader.error("truth row has too few columns");
    const auto week = io::parse_int(fields[layout.week]);
    const auto cycle = layout.cycle ? io::parse_int(fields[*layout.cycle]) : std::optional<int>(0);
    const auto tow = io::parse_double(fields[layout.tow]);
    const auto x = io::parse_double(fields[layout.xyz[0]]);
    const auto y = io::parse_double(fields[layout.xyz[1]]);
    const auto z = io::parse_double(fields[layout.xyz[2]]);
    if (!week || !cycle || !tow || !x || !y || !z) return reader.error("bad number in truth row");
    const core::GpsTime time = core::GpsTime{*cycle * 1024 + *week, *tow}.normalized();
    if (!samples.empty() && !(samples.back().time < time)) {
      return reader.error("truth times are not strictly increasing");
    }
    samples.push_back({time, Eigen::Vector3d(*x, *y, *z)});
  }
  if (reader.read_error()) return reader.error(*reader.read_error());
  if (samples.empty()) return Error{"truth file has no samples", reader.path(), 0};
  return Truth::from_samples(std::move(samples), options);
}

Result<std::vector<double>> parse_numbers(std::string_view text, std::size_t count, const std::string& spec) {
  const auto fields = split_commas(text);
  std::vector<double> values;
  for (const auto field : fields) {
    const auto v = io::parse_double(field);
    if (!v) break;
    values.push_back(*v);
  }
  if (values.size() != count || fields.size() != count) {
    return Error{"truth '" + spec + "': expected " + std::to_string(count) + " comma-separated numbers"};
  }
  return values;
}

bool ends_with(std::string_view text, std::string_view suffix) {
  return text.size() >= suffix.size() && text.substr(text.size() - suffix.size()) == suffix;
}

}  // namespace

Truth Truth::constant(const Eigen::Vector3d& p_E_m) {
  return Truth({TruthSample{core::GpsTime{}, p_E_m}}, TruthOptions{}, true);
}

Result<Truth> Truth::from_samples(std::vector<TruthSample> samples, TruthOptions options) {
  if (samples.empty()) return Error{"truth has no samples"};
  for (std::size_t i = 1; i < samples.size(); ++i) {
    if (!(samples[i - 1].time < samples[i].time)) {
      return Error{"truth sample " + std::to_string(i) + " is not later than the one before"};
    }
  }
  return Truth(std::move(samples), options, false);
}

std::optional<Eigen::Vector3d> Truth::position_at(const core::GpsTime& time) const {
  if (constant_) return samples_.front().p_E_m;
  const auto after = std::lower_bound(samples_.begin(), samples_.end(), time,
                                      [](const TruthSample& s, const core::GpsTime& t) { return s.time < t; });
  if (after != samples_.end() && std::abs(after->time - time) < 1e-9) return after->p_E_m;
  if (samples_.size() == 1) {
    if (std::abs(time - samples_.front().time) <= options_.max_extrapolation_s) return samples_.front().p_E_m;
    return std::nullopt;
  }
  // Segment [a, b] used for interpolation (inside) or extrapolation (the end segments).
  auto b = after;
  if (b == samples_.begin()) {
    if (samples_.front().time - time > options_.max_extrapolation_s) return std::nullopt;
    b = samples_.begin() + 1;
  } else if (b == samples_.end()) {
    if (time - samples_.back().time > options_.max_extrapolation_s) return std::nullopt;
    b = samples_.end() - 1;
  }
  const auto a = b - 1;
  const double span_s = b->time - a->time;
  if (span_s > options_.max_gap_s) return std::nullopt;
  const double fraction = (time - a->time) / span_s;
  return a->p_E_m + fraction * (b->p_E_m - a->p_E_m);
}

Result<Truth> read_spirent_pva_csv(const std::string& path, TruthOptions options) {
  auto reader = io::TextReader::open(path);
  if (!reader) return reader.error();
  const auto header_line = reader->next_line();
  if (!header_line) return Error{"empty truth file", path, 0};
  const auto header = split_commas(*header_line);
  CsvLayout layout;
  const std::array<std::string_view, 5> names = {"GpsWeek", "GpsToW [s]", "Pos ECEF X [m]", "Pos ECEF Y [m]",
                                                 "Pos ECEF Z [m]"};
  std::array<std::size_t, 5> index{};
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto column = find_column(header, names[i]);
    if (!column) return reader->error("Spirent PVA header has no column '" + std::string(names[i]) + "'");
    index[i] = *column;
  }
  layout.cycle = find_column(header, "GpsCycle");
  layout.week = index[0];
  layout.tow = index[1];
  layout.xyz = {index[2], index[3], index[4]};
  return read_csv_with_layout(*reader, layout, options);
}

Result<Truth> read_truth_csv(const std::string& path, TruthOptions options) {
  auto reader = io::TextReader::open(path);
  if (!reader) return reader.error();
  const auto header_line = reader->next_line();
  if (!header_line) return Error{"empty truth file", path, 0};
  const auto header = split_commas(*header_line);
  const std::array<std::string_view, 5> names = {"gps_week", "gps_tow_s", "x", "y", "z"};
  std::array<std::size_t, 5> index{};
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto column = find_column(header, names[i]);
    if (!column) return reader->error("truth CSV header has no column '" + std::string(names[i]) + "'");
    index[i] = *column;
  }
  CsvLayout layout;
  layout.week = index[0];
  layout.tow = index[1];
  layout.xyz = {index[2], index[3], index[4]};
  return read_csv_with_layout(*reader, layout, options);
}

Result<Truth> read_truth_pos(const std::string& path, TruthOptions options) {
  auto solutions = io::read_pos_file(path);
  if (!solutions) return solutions.error();
  std::vector<TruthSample> samples;
  samples.reserve(solutions->size());
  for (const auto& s : *solutions) samples.push_back({s.time.normalized(), s.p_E_m});
  if (samples.empty()) return Error{"truth file has no records", path, 0};
  auto truth = Truth::from_samples(std::move(samples), options);
  if (!truth) return Error{truth.error().message, path, 0};
  return truth;
}

Result<Truth> parse_truth_spec(const std::string& spec, TruthOptions options) {
  const std::string_view text = spec;
  if (text.rfind("ecef:", 0) == 0) {
    auto v = parse_numbers(text.substr(5), 3, spec);
    if (!v) return v.error();
    return Truth::constant(Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]));
  }
  if (text.rfind("llh:", 0) == 0) {
    auto v = parse_numbers(text.substr(4), 3, spec);
    if (!v) return v.error();
    const double lat_deg = (*v)[0];
    const double lon_deg = (*v)[1];
    if (std::abs(lat_deg) > 90.0 || std::abs(lon_deg) > 360.0) {
      return Error{"truth '" + spec + "': latitude or longitude out of range"};
    }
    const core::Geodetic g{lat_deg * core::kDegToRad, lon_deg * core::kDegToRad, (*v)[2]};
    return Truth::constant(core::geodetic_to_ecef(g));
  }
  if (spec.empty()) return Error{"empty truth specification"};
  if (ends_with(text, ".csv") || ends_with(text, ".CSV")) {
    auto reader = io::TextReader::open(spec);
    if (!reader) return reader.error();
    const auto header = reader->next_line();
    if (header && header->find("GpsToW") != std::string_view::npos) return read_spirent_pva_csv(spec, options);
    return read_truth_csv(spec, options);
  }
  return read_truth_pos(spec, options);
}

}  // namespace canyon::eval
