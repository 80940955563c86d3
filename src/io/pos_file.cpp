// RTKLIB-compatible .pos solution files: writer and reader (format in pos_file.hpp).

#include "canyon/io/pos_file.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string_view>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/io/number_format.hpp"
#include "canyon/io/text_reader.hpp"

namespace canyon::io {
namespace {

double signed_sqrt(double c) {
  return c < 0.0 ? -std::sqrt(-c) : std::sqrt(c);
}
double signed_square(double s) {
  return s < 0.0 ? -s * s : s * s;
}

std::string format_time(const core::GpsTime& t, PosTimeFormat format) {
  char buffer[64];
  // Round to the printed millisecond first so that 59.9996 s does not print as 60.000.
  core::GpsTime r = t.normalized();
  r.tow_s = std::round(r.tow_s * 1000.0) / 1000.0;
  r = r.normalized();
  if (format == PosTimeFormat::WeekTow) {
    std::string out;
    append_int(out, r.week, 4);
    out += ' ';
    append_fixed(out, r.tow_s, 10, 3);
    return out;
  } else {
    const core::CalendarTime c = core::gps_to_calendar(r);
    std::snprintf(buffer, sizeof buffer, "%04d/%02d/%02d %02d:%02d:%06.3f", c.year, c.month, c.day, c.hour, c.minute,
                  c.second);
  }
  return buffer;
}

std::string column_titles(PosCoordinates coordinates, PosTimeFormat time_format) {
  const char* time = time_format == PosTimeFormat::WeekTow ? "%  GPST          " : "%  GPST                  ";
  if (coordinates == PosCoordinates::Llh) {
    return std::string(time) +
           "latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) "
           "age(s)  ratio";
  }
  return std::string(time) +
         "  x-ecef(m)      y-ecef(m)      z-ecef(m)   Q  ns   sdx(m)   sdy(m)   sdz(m)  sdxy(m)  sdyz(m)  sdzx(m) "
         "age(s)  ratio";
}

}  // namespace

Result<PosWriter> PosWriter::create(const std::string& path, PosWriterOptions options) {
  auto file = TextFileWriter::create(path, "solution file");
  if (!file) return file.error();
  for (const std::string& line : options.header_lines) {
    if (Status s = file->write_line("% " + line); !s) return s.error();
  }
  const char* coordinates =
      options.coordinates == PosCoordinates::Llh ? "lat/lon/height=WGS84/ellipsoidal" : "x/y/z-ecef=WGS84";
  if (Status s = file->write_line("%"); !s) return s.error();
  if (Status s = file->write_line(std::string("% (") + coordinates +
                                  ",Q=1:fix,2:float,5:single,7:vio fill-in,ns=# of satellites)");
      !s) {
    return s.error();
  }
  if (Status s = file->write_line(column_titles(options.coordinates, options.time_format)); !s) return s.error();
  return PosWriter(std::move(*file), std::move(options));
}

std::string format_pos_record(const core::Solution& s, PosCoordinates coordinates, PosTimeFormat time_format) {
  std::string line = format_time(s.time, time_format);
  line.reserve(160);
  double sd[6];
  if (coordinates == PosCoordinates::Llh) {
    const core::Geodetic g = core::ecef_to_geodetic(s.p_E_m);
    const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(g);
    const Eigen::Matrix3d P_N = R_NE * s.P_E_m2 * R_NE.transpose();
    line += ' ';
    append_fixed(line, g.lat_rad * core::kRadToDeg, 14, 9);
    line += ' ';
    append_fixed(line, g.lon_rad * core::kRadToDeg, 14, 9);
    line += ' ';
    append_fixed(line, g.height_m, 10, 4);
    // sdn sde sdu sdne sdeu sdun
    sd[0] = std::sqrt(std::max(P_N(1, 1), 0.0));
    sd[1] = std::sqrt(std::max(P_N(0, 0), 0.0));
    sd[2] = std::sqrt(std::max(P_N(2, 2), 0.0));
    sd[3] = signed_sqrt(P_N(1, 0));
    sd[4] = signed_sqrt(P_N(0, 2));
    sd[5] = signed_sqrt(P_N(2, 1));
  } else {
    const Eigen::Matrix3d& P = s.P_E_m2;
    for (int i = 0; i < 3; ++i) {
      line += ' ';
      append_fixed(line, s.p_E_m[i], 14, 4);
    }
    // sdx sdy sdz sdxy sdyz sdzx
    sd[0] = std::sqrt(std::max(P(0, 0), 0.0));
    sd[1] = std::sqrt(std::max(P(1, 1), 0.0));
    sd[2] = std::sqrt(std::max(P(2, 2), 0.0));
    sd[3] = signed_sqrt(P(0, 1));
    sd[4] = signed_sqrt(P(1, 2));
    sd[5] = signed_sqrt(P(2, 0));
  }
  line += ' ';
  append_int(line, static_cast<int>(s.status), 3);
  line += ' ';
  append_int(line, s.num_satellites, 3);
  for (const double v : sd) {
    line += ' ';
    append_fixed(line, v, 8, 4);
  }
  line += ' ';
  append_fixed(line, s.age_s, 6, 2);
  line += ' ';
  append_fixed(line, s.ratio, 6, 1);
  return line;
}

Status PosWriter::write(const core::Solution& solution) {
  return file_.write_line(format_pos_record(solution, options_.coordinates, options_.time_format));
}

namespace {

// ---- Reading ----------------------------------------------------------------------------------------------------

enum class TimeSystem { Gpst, Utc, Jst };
/// How the three (dms: seven) position values of a record are to be read.
enum class PositionForm { Guess, LlhDegrees, LlhDms, Ecef, EnuBaseline };

constexpr double kJstMinusUtcS = 9.0 * 3600.0;

/// What the header says about the records (RTKLIB's output options).
struct PosLayout {
  TimeSystem time_system = TimeSystem::Gpst;
  PositionForm form = PositionForm::Guess;
  std::string separators = " \t";  ///< blanks and RTKLIB's out-fieldsep characters
  std::string ref_pos_text;        ///< after "% ref pos :", parsed once the form is known
  int ref_pos_line = 0;
  std::optional<Eigen::Vector3d> p_E_ref_m;  ///< base position of an e/n/u baseline solution
};

/// Fields of `text` separated by any run of `separators`.
std::vector<std::string_view> split_fields(std::string_view text, std::string_view separators) {
  std::vector<std::string_view> fields;
  std::size_t start = text.find_first_not_of(separators);
  while (start != std::string_view::npos) {
    const std::size_t end = text.find_first_of(separators, start);
    fields.push_back(text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    start = end == std::string_view::npos ? end : text.find_first_not_of(separators, end);
  }
  return fields;
}

bool contains(std::string_view text, std::string_view what) {
  return text.find(what) != std::string_view::npos;
}

/// Characters RTKLIB's column titles are made of; any other character there is a field separator (out-fieldsep).
bool is_title_character(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 ||
         std::string_view(" \t()'\"-/_%#.=").find(c) != std::string_view::npos;
}

/// The column titles line, "%  GPST  latitude(deg) ..." (also UTC, JST): time system, position form, separators.
/// Returns false if `line` is not one.
bool parse_column_titles(std::string_view line, PosLayout& layout) {
  const std::string_view titles = trim(line.substr(1));
  const auto word_end = titles.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZ");
  const std::string_view word = titles.substr(0, word_end);
  if (word != "GPST" && word != "UTC" && word != "JST") return false;
  if (!contains(titles, "latitude(") && !contains(titles, "x-ecef(") && !contains(titles, "e-baseline(")) return false;
  layout.time_system = word == "GPST" ? TimeSystem::Gpst : word == "UTC" ? TimeSystem::Utc : TimeSystem::Jst;
  if (contains(titles, "latitude(d'\")")) {
    layout.form = PositionForm::LlhDms;
  } else if (contains(titles, "latitude(")) {
    layout.form = PositionForm::LlhDegrees;
  } else if (contains(titles, "x-ecef(")) {
    layout.form = PositionForm::Ecef;
  } else {
    layout.form = PositionForm::EnuBaseline;
  }
  for (const char c : titles) {
    if (!is_title_character(c) && layout.separators.find(c) == std::string::npos) layout.separators += c;
  }
  return true;
}

/// Degrees from RTKLIB's "d m s" fields; the sign is on the degrees ("-0 30 00.0" is -0.5).
std::optional<double> dms_to_degrees(std::string_view d, std::string_view m, std::string_view s) {
  const auto deg = parse_double(d);
  const auto min = parse_double(m);
  const auto sec = parse_double(s);
  if (!deg || !min || !sec || *min < 0.0 || *min >= 60.0 || *sec < 0.0 || *sec >= 60.0) return std::nullopt;
  const double magnitude = std::abs(*deg) + *min / 60.0 + *sec / 3600.0;
  return trim(d).front() == '-' ? -magnitude : magnitude;
}

/// Latitude, longitude (deg) and height of 3 (decimal degrees) or 7 (d m s) fields.
std::optional<Eigen::Vector3d> parse_llh_fields(const std::vector<std::string_view>& f, std::size_t first, bool dms) {
  std::optional<double> lat, lon, h;
  if (dms) {
    lat = dms_to_degrees(f[first], f[first + 1], f[first + 2]);
    lon = dms_to_degrees(f[first + 3], f[first + 4], f[first + 5]);
    h = parse_double(f[first + 6]);
  } else {
    lat = parse_double(f[first]);
    lon = parse_double(f[first + 1]);
    h = parse_double(f[first + 2]);
  }
  if (!lat || !lon || !h || std::abs(*lat) > 90.0 || std::abs(*lon) > 360.0) return std::nullopt;
  return Eigen::Vector3d(*lat, *lon, *h);
}

Eigen::Vector3d llh_degrees_to_ecef(const Eigen::Vector3d& llh) {
  return core::geodetic_to_ecef({llh.x() * core::kDegToRad, llh.y() * core::kDegToRad, llh.z()});
}

/// The "% ref pos" line in the form of the records: ECEF, decimal degrees or d m s (ENU files: the degree form).
Status parse_ref_pos(PosLayout& layout, const std::string& path) {
  if (layout.ref_pos_text.empty()) return Ok{};
  const auto f = split_fields(layout.ref_pos_text, layout.separators);
  const Error bad{"bad base position in the '% ref pos' line", path, layout.ref_pos_line};
  if (layout.form == PositionForm::Ecef) {
    if (f.size() != 3) return bad;
    const auto x = parse_double(f[0]), y = parse_double(f[1]), z = parse_double(f[2]);
    if (!x || !y || !z) return bad;
    layout.p_E_ref_m = Eigen::Vector3d(*x, *y, *z);
    return Ok{};
  }
  if (f.size() != 3 && f.size() != 7) return bad;
  const auto llh = parse_llh_fields(f, 0, f.size() == 7);
  if (!llh) return bad;
  layout.p_E_ref_m = llh_degrees_to_ecef(*llh);
  return Ok{};
}

/// Reads a header line into `layout`. Error for heights above the geoid.
Status parse_header_line(std::string_view line, PosLayout& layout, const TextReader& reader) {
  if (contains(line, "lat/lon/height=") && contains(line, "/geodetic")) {
    return reader.error(
        "heights above the geoid (RTKLIB out-height=geodetic) cannot be converted to ECEF without RTKLIB's geoid "
        "model: write ellipsoidal heights");
  }
  const std::string_view text = trim(line.substr(1));
  if (text.rfind("ref pos", 0) == 0) {
    const std::size_t colon = text.find(':');
    if (colon == std::string_view::npos) return reader.error("bad '% ref pos' line");
    layout.ref_pos_text = std::string(text.substr(colon + 1));
    layout.ref_pos_line = reader.line_number();
    return Ok{};
  }
  if (parse_column_titles(line, layout)) return parse_ref_pos(layout, reader.path());
  return Ok{};
}

/// GPST of the time fields, on the file's time scale. RTKLIB writes a UTC or JST instant as if it were GPST (also
/// as week and seconds), so both forms are read on the GPST scale first and then shifted.
Result<core::GpsTime> parse_record_time(std::string_view first, std::string_view second, TimeSystem system,
                                        const core::LeapSecondTable& leaps, const TextReader& reader) {
  core::GpsTime label;
  if (contains(first, "/")) {
    core::CalendarTime c;
    const std::string date(first), clock(second);
    char tail = 0;
    if (std::sscanf(date.c_str(), "%d/%d/%d%c", &c.year, &c.month, &c.day, &tail) != 3 ||
        std::sscanf(clock.c_str(), "%d:%d:%lf%c", &c.hour, &c.minute, &c.second, &tail) != 3 || !core::is_valid(c)) {
      return reader.error("bad date/time '" + date + " " + clock + "'");
    }
    label = core::calendar_to_gps(c);
  } else {
    const auto week = parse_int(first);
    const auto tow = parse_double(second);
    if (!week || !tow || *week < 0 || *tow < 0.0 || *tow >= 2.0 * core::kSecondsPerWeek) {
      return reader.error("bad GPST week/time of week '" + std::string(first) + " " + std::string(second) + "'");
    }
    label = core::GpsTime{*week, *tow};
  }
  if (system == TimeSystem::Gpst) return label;
  if (system == TimeSystem::Jst) label = label - kJstMinusUtcS;
  return core::utc_to_gps(core::gps_to_calendar(label.normalized()), leaps);
}

Eigen::Matrix3d symmetric_from_sd(double s00, double s11, double s22, double c01, double c12, double c20) {
  Eigen::Matrix3d P;
  P << s00 * s00, signed_square(c01), signed_square(c20), signed_square(c01), s11 * s11, signed_square(c12),
      signed_square(c20), signed_square(c12), s22 * s22;
  return P;
}

/// The six standard deviation columns of a record, in the file's order.
using StandardDeviations = std::array<double, 6>;

/// Position and covariance (ECEF) of the position and standard deviation fields.
Status set_position(core::Solution& s, const std::vector<std::string_view>& f, std::size_t first, PositionForm form,
                    const StandardDeviations& sd, const PosLayout& layout, const TextReader& reader) {
  if (form == PositionForm::LlhDegrees || form == PositionForm::LlhDms) {
    const auto llh = parse_llh_fields(f, first, form == PositionForm::LlhDms);
    if (!llh) return reader.error("bad latitude/longitude/height");
    s.p_E_m = llh_degrees_to_ecef(*llh);
    const core::Geodetic g{llh->x() * core::kDegToRad, llh->y() * core::kDegToRad, llh->z()};
    // sdn sde sdu sdne sdeu sdun -> ENU covariance
    const Eigen::Matrix3d P_N = symmetric_from_sd(sd[1], sd[0], sd[2], sd[3], sd[5], sd[4]);
    const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(g);
    s.P_E_m2 = R_NE.transpose() * P_N * R_NE;
    return Ok{};
  }
  const auto a = parse_double(f[first]), b = parse_double(f[first + 1]), c = parse_double(f[first + 2]);
  if (!a || !b || !c) return reader.error("bad position fields");
  if (form == PositionForm::Ecef) {
    s.p_E_m = Eigen::Vector3d(*a, *b, *c);
    // sdx sdy sdz sdxy sdyz sdzx
    s.P_E_m2 = symmetric_from_sd(sd[0], sd[1], sd[2], sd[3], sd[4], sd[5]);
    return Ok{};
  }
  // e/n/u baseline from the base, ENU at the base; sde sdn sdu sden sdnu sdue
  if (!layout.p_E_ref_m) {
    return reader.error(
        "e/n/u baseline solution (RTKLIB out-solformat=enu) without a '% ref pos' header line: the base position "
        "is unknown");
  }
  const core::Geodetic base = core::ecef_to_geodetic(*layout.p_E_ref_m);
  const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(base);
  s.p_E_m = *layout.p_E_ref_m + R_NE.transpose() * Eigen::Vector3d(*a, *b, *c);
  const Eigen::Matrix3d P_N = symmetric_from_sd(sd[0], sd[1], sd[2], sd[3], sd[4], sd[5]);
  s.P_E_m2 = R_NE.transpose() * P_N * R_NE;
  return Ok{};
}

/// Without column titles: latitude/longitude/height when the values look like it, else ECEF.
PositionForm guess_form(const std::vector<std::string_view>& f, std::size_t first) {
  const auto a = parse_double(f[first]), b = parse_double(f[first + 1]), c = parse_double(f[first + 2]);
  if (!a || !b || !c) return PositionForm::Ecef;  // reported as bad position fields
  const bool llh = std::abs(*a) <= 90.0 && std::abs(*b) <= 360.0 && std::abs(*c) < 1e5;
  return llh ? PositionForm::LlhDegrees : PositionForm::Ecef;
}

Result<core::Solution> parse_record(std::string_view text, const PosLayout& layout, const core::LeapSecondTable& leaps,
                                    const TextReader& reader) {
  if (text.front() == '$') {
    return reader.error("NMEA sentence (RTKLIB out-solformat=nmea), not a .pos record: write llh, xyz or enu");
  }
  const auto f = split_fields(text, layout.separators);
  const std::size_t position_fields = layout.form == PositionForm::LlhDms ? 7 : 3;
  const std::size_t q_index = 2 + position_fields;
  if (f.size() < q_index + 2) {
    return reader.error("record has " + std::to_string(f.size()) + " fields, expected at least " +
                        std::to_string(q_index + 2) + " (time, position, Q, ns)");
  }
  core::Solution s;
  auto time = parse_record_time(f[0], f[1], layout.time_system, leaps, reader);
  if (!time) return time.error();
  s.time = *time;
  const auto q = parse_int(f[q_index]);
  const auto ns = parse_int(f[q_index + 1]);
  if (!q || *q < 0 || *q > 7) return reader.error("bad solution status Q '" + std::string(f[q_index]) + "'");
  if (!ns || *ns < 0) return reader.error("bad number of satellites '" + std::string(f[q_index + 1]) + "'");
  s.status = static_cast<core::SolutionStatus>(*q);
  s.num_satellites = *ns;
  // Optional: six standard deviations, age, ratio (then RTKLIB's velocity columns, ignored).
  std::array<double, 8> optional_values{};
  for (std::size_t k = 0; k < optional_values.size() && q_index + 2 + k < f.size(); ++k) {
    const auto v = parse_double(f[q_index + 2 + k]);
    if (!v) return reader.error("bad number '" + std::string(f[q_index + 2 + k]) + "'");
    optional_values[k] = *v;
  }
  StandardDeviations sd{};
  std::copy_n(optional_values.begin(), sd.size(), sd.begin());
  s.age_s = optional_values[6];
  s.ratio = optional_values[7];
  const PositionForm form = layout.form == PositionForm::Guess ? guess_form(f, 2) : layout.form;
  if (Status st = set_position(s, f, 2, form, sd, layout, reader); !st) return st.error();
  return s;
}

}  // namespace

Result<std::vector<core::Solution>> read_pos_file(const std::string& path, const core::LeapSecondTable& leaps) {
  auto reader = TextReader::open(path);
  if (!reader) return reader.error();
  std::vector<core::Solution> out;
  PosLayout layout;
  while (auto line = reader->next_line()) {
    const std::string_view text = trim(*line);
    if (text.empty()) continue;
    if (text.front() == '%') {
      if (Status s = parse_header_line(text, layout, *reader); !s) return s.error();
      continue;
    }
    auto solution = parse_record(text, layout, leaps, *reader);
    if (!solution) return solution.error();
    out.push_back(*solution);
  }
  if (reader->read_error()) return reader->error(*reader->read_error());
  return out;
}

Result<std::vector<core::Solution>> read_pos_file(const std::string& path) {
  return read_pos_file(path, core::builtin_leap_seconds());
}

}  // namespace canyon::io
