// vio.csv and timesync.csv readers (contract and handling of bad input in vio_file.hpp).

#include "canyon/io/vio_file.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string_view>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "canyon/io/text_reader.hpp"

namespace canyon::io {
namespace {

constexpr int kPoseFields = 8;
constexpr std::array<std::string_view, kPoseFields> kNames = {"t_ns", "px", "py", "pz", "qx", "qy", "qz", "qw"};
constexpr int kCovarianceFields = 21;
constexpr int kCrossFields = 36;
constexpr std::size_t kMaxWarningsPerKind = 5;

/// The fields of a CSV line into `fields` (reused between lines).
void split_csv(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(
        trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
}

std::vector<std::string_view> split_csv(std::string_view line) {
  std::vector<std::string_view> fields;
  split_csv(line, fields);
  return fields;
}

std::optional<std::int64_t> parse_int64(std::string_view field) {
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (ec != std::errc{} || end != field.data() + field.size() || field.empty()) return std::nullopt;
  return value;
}

/// Warnings of one kind: the first few in full, then a count.
class WarningList {
 public:
  WarningList(std::vector<std::string>& out, std::string summary) : out_(out), summary_(std::move(summary)) {}
  void add(std::string text) {
    if (count_++ < kMaxWarningsPerKind) out_.push_back(std::move(text));
  }
  void finish(const std::string& path) {
    if (count_ > kMaxWarningsPerKind) {
      out_.push_back(path + ": " + std::to_string(count_) + " " + summary_ + " in all (the first " +
                     std::to_string(kMaxWarningsPerKind) + " listed)");
    }
  }

 private:
  std::vector<std::string>& out_;
  std::string summary_;
  std::size_t count_ = 0;
};

/// The numbers of a data row (after the integer time), or an Error at the reader's line.
Result<std::vector<double>> parse_numbers(const std::vector<std::string_view>& fields, std::size_t first,
                                          const TextReader& reader, const std::vector<std::string>& names) {
  std::vector<double> values;
  values.reserve(fields.size() - first);
  for (std::size_t i = first; i < fields.size(); ++i) {
    const auto v = parse_double(fields[i]);
    if (!v) return reader.error("field " + names[i] + " is not a number: '" + std::string(fields[i]) + "'");
    if (!std::isfinite(*v)) return reader.error("field " + names[i] + " is not finite");
    values.push_back(*v);
  }
  return values;
}

}  // namespace

std::string vio_csv_header() {
  std::string header;
  for (int i = 0; i < kPoseFields; ++i)
    header += std::string(i > 0 ? "," : "") + std::string(kNames[static_cast<std::size_t>(i)]);
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) header += ",cov_" + std::to_string(r) + "_" + std::to_string(c);
  }
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) header += ",xcov_" + std::to_string(r) + "_" + std::to_string(c);
  }
  return header;
}

std::string timesync_csv_header() {
  return "t_ns,gps_week,gps_tow_s";
}

std::string timesync_csv_row(const TimeSyncPair& pair) {
  char line[96];
  std::snprintf(line, sizeof line, "%lld,%d,%.17g", static_cast<long long>(pair.t_ns), pair.time.week, pair.time.tow_s);
  return line;
}

std::string vio_csv_row(const VioRecord& record) {
  std::string row = std::to_string(record.t_ns);
  char value[32];
  const auto add = [&](double v) {
    std::snprintf(value, sizeof value, ",%.17g", v);
    row += value;
  };
  const core::Pose& T = record.T_OI;
  for (const double v : {T.p.x(), T.p.y(), T.p.z(), T.q.x(), T.q.y(), T.q.z(), T.q.w()}) add(v);
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) add(record.covariance(r, c));
  }
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) add(record.cross_previous ? (*record.cross_previous)(r, c) : 0.0);
  }
  return row;
}

Result<VioFile> read_vio_csv(const std::string& path) {
  auto opened = TextReader::open(path);
  if (!opened) return opened.error();
  TextReader& reader = *opened;
  const auto header_line = reader.next_line();
  if (!header_line) return Error{"empty VIO file (no header row)", path, 1};
  const std::vector<std::string_view> header = split_csv(*header_line);
  const auto columns = static_cast<int>(header.size());
  bool header_ok =
      columns == kPoseFields + kCovarianceFields || columns == kPoseFields + kCovarianceFields + kCrossFields;
  for (int i = 0; header_ok && i < kPoseFields; ++i) header_ok = header[static_cast<std::size_t>(i)] == kNames[i];
  if (!header_ok) {
    return reader.error(
        "not a VIO file: the header row must be t_ns,px,py,pz,qx,qy,qz,qw then 21 covariance columns "
        "and optionally 36 cross-covariance columns (" +
        std::to_string(kPoseFields + kCovarianceFields) + " or " +
        std::to_string(kPoseFields + kCovarianceFields + kCrossFields) + " columns, found " + std::to_string(columns) +
        ")");
  }
  std::vector<std::string> names;
  names.reserve(header.size());
  for (const std::string_view h : header) names.emplace_back(h);

  VioFile file;
  file.has_cross_covariance = columns == kPoseFields + kCovarianceFields + kCrossFields;
  WarningList non_monotonic(file.warnings, "poses dropped for a time not after the previous pose's");
  WarningList not_pd(file.warnings, "poses dropped for a covariance that is not positive definite");
  bool previous_dropped = false;
  std::vector<std::string_view> fields;
  while (const auto line = reader.next_line()) {
    if (trim(*line).empty()) continue;
    split_csv(*line, fields);
    if (static_cast<int>(fields.size()) != columns) {
      const Error bad = reader.error("expected " + std::to_string(columns) + " fields as in the header, found " +
                                     std::to_string(fields.size()));
      if (reader.line_cut() || !reader.next_line()) {
        file.warnings.push_back(bad.to_string() + ": the last row, cut short, dropped");
        break;
      }
      return bad;
    }
    const auto t_ns = parse_int64(fields[0]);
    if (!t_ns) return reader.error("t_ns is not an integer (ns): '" + std::string(fields[0]) + "'");
    auto values = parse_numbers(fields, 1, reader, names);
    if (!values) return values.error();
    const std::vector<double>& v = *values;
    VioRecord r;
    r.t_ns = *t_ns;
    r.line = reader.line_number();
    r.T_OI.p = Eigen::Vector3d(v[0], v[1], v[2]);
    const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
    const double norm = q.norm();
    if (!(norm >= 0.5 && norm <= 1.5)) {
      return reader.error("quaternion (qx, qy, qz, qw) has norm " + std::to_string(norm) + ", not a rotation");
    }
    r.T_OI.q = q.normalized();
    std::size_t k = kPoseFields - 1;
    for (int row = 0; row < 6; ++row) {
      for (int col = row; col < 6; ++col) {
        r.covariance(row, col) = r.covariance(col, row) = v[k++];
      }
    }
    if (file.has_cross_covariance) {
      core::Matrix6d c;
      for (int row = 0; row < 6; ++row) {
        for (int col = 0; col < 6; ++col) c(row, col) = v[k++];
      }
      r.cross_previous = c;
    }
    if (!file.records.empty() && r.t_ns <= file.records.back().t_ns) {
      ++file.dropped_non_monotonic;
      non_monotonic.add(reader
                            .error("time " + std::to_string(r.t_ns) + " ns is not after the previous pose's " +
                                   std::to_string(file.records.back().t_ns) + " ns (non-monotonic): pose dropped")
                            .to_string());
      previous_dropped = true;
      continue;
    }
    // Cholesky succeeds exactly for a positive definite matrix; the eigenvalues are only for the message.
    if (Eigen::LLT<core::Matrix6d>(r.covariance).info() != Eigen::Success) {
      const double smallest =
          Eigen::SelfAdjointEigenSolver<core::Matrix6d>(r.covariance, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
      ++file.dropped_not_positive_definite;
      not_pd.add(reader
                     .error("covariance is not positive definite (smallest eigenvalue " + std::to_string(smallest) +
                            "): pose dropped")
                     .to_string());
      previous_dropped = true;
      continue;
    }
    // The first kept row has no predecessor; after a dropped row the cross-covariance refers to the dropped pose.
    if (file.records.empty() || previous_dropped) r.cross_previous.reset();
    previous_dropped = false;
    file.records.push_back(r);
  }
  if (const auto& e = reader.read_error()) return Error{"read error: " + *e, path, reader.line_number()};
  non_monotonic.finish(path);
  not_pd.finish(path);
  if (file.records.empty()) return Error{"no usable pose in the VIO file", path, reader.line_number()};
  return file;
}

Result<TimeSyncFile> read_timesync_csv(const std::string& path) {
  auto opened = TextReader::open(path);
  if (!opened) return opened.error();
  TextReader& reader = *opened;
  const auto header_line = reader.next_line();
  if (!header_line) return Error{"empty time-sync file (no header row)", path, 1};
  const std::vector<std::string_view> header = split_csv(*header_line);
  if (header.size() != 3 || header[0] != "t_ns" || header[1] != "gps_week" || header[2] != "gps_tow_s") {
    return reader.error("not a time-sync file: the header row must be t_ns,gps_week,gps_tow_s");
  }
  TimeSyncFile file;
  while (const auto line = reader.next_line()) {
    if (trim(*line).empty()) continue;
    const std::vector<std::string_view> fields = split_csv(*line);
    if (fields.size() != 3) {
      const Error bad =
          reader.error("expected 3 fields (t_ns,gps_week,gps_tow_s), found " + std::to_string(fields.size()));
      if (reader.line_cut() || !reader.next_line()) {
        file.warnings.push_back(bad.to_string() + ": the last row, cut short, dropped");
        break;
      }
      return bad;
    }
    const auto t_ns = parse_int64(fields[0]);
    if (!t_ns) return reader.error("t_ns is not an integer (ns): '" + std::string(fields[0]) + "'");
    const auto week = parse_int(fields[1]);
    if (!week || *week < 0) return reader.error("gps_week is not a week number: '" + std::string(fields[1]) + "'");
    const auto tow = parse_double(fields[2]);
    if (!tow || !(*tow >= 0.0 && *tow < core::kSecondsPerWeek)) {
      return reader.error("gps_tow_s is not a time of week in [0, 604800) s: '" + std::string(fields[2]) + "'");
    }
    file.pairs.push_back(TimeSyncPair{*t_ns, core::GpsTime{*week, *tow}, reader.line_number()});
  }
  if (const auto& e = reader.read_error()) return Error{"read error: " + *e, path, reader.line_number()};
  if (file.pairs.empty()) return Error{"no time-sync pair in the file", path, reader.line_number()};
  return file;
}

}  // namespace canyon::io
