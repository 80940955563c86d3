// RINEX navigation reader (2.x GPS 'N' and GLONASS 'G', 3.x mixed) and RINEX 3.04 mixed navigation writer.
//
// Record layouts (RINEX 3.04 section A.8-A.17, RINEX 2.11 table A4/A11): a first line with the satellite, the epoch
// and three D19.12 numbers, then "broadcast orbit" lines of four D19.12 numbers after a 4 (v3) or 3 (v2) character
// indent. GPS/QZSS/Galileo/BeiDou records have 7 orbit lines, GLONASS 3 (4 in RINEX >= 3.05), SBAS 3, IRNSS 7.
// Every time is converted to GPST here: GPS/QZSS/Galileo epochs are on the GPST calendar (GST = GPST), BeiDou epochs
// on BDT (GPST = BDT + 14 s), GLONASS epochs in UTC (GPST = UTC + leap seconds, from the header or the table).

#include "canyon/io/rinex_nav.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string_view>

#include "canyon/io/text_reader.hpp"

namespace canyon::io {
namespace {

using core::CalendarTime;
using core::Constellation;
using core::GpsTime;
using core::kSecondsPerDay;
using core::kSecondsPerWeek;

constexpr int kKeplerOrbitLines = 7;
constexpr int kGlonassOrbitLines = 3;
constexpr int kSbasOrbitLines = 3;

struct Header {
  double version = 0.0;
  char file_type = ' ';  // 'N' or 'G' (RINEX 2 GLONASS)
  char system = ' ';     // RINEX 3 satellite system of the file, or ' '
};

/// Result of parsing one record line's numbers.
struct Numbers {
  std::vector<double> values;
};

/// The GPST instant nearest to `reference` among `t + k * period_s`.
GpsTime nearest_by_period(GpsTime t, const GpsTime& reference, double period_s) {
  const double d_s = t - reference;
  const double k = std::round(d_s / period_s);
  return t - k * period_s;
}

class NavParser {
 public:
  NavParser(TextReader reader, const core::LeapSecondTable& leaps) : reader_(std::move(reader)), leaps_(leaps) {}

  Result<RinexNavFile> parse() {
    Status header = parse_header();
    if (!header.ok()) return header.error();
    while (true) {
      const std::optional<std::string_view> line = reader_.next_line();
      if (!line) break;
      if (trim(*line).empty()) continue;
      Status record = parse_record(std::string(*line));
      if (!record.ok()) return record.error();
    }
    if (reader_.read_error()) return reader_.error(*reader_.read_error());
    if (skipped_ > 0) {
      out_.warnings.push_back(reader_.path() + ": skipped " + std::to_string(skipped_) +
                              " SBAS/IRNSS/unsupported-system records");
    }
    return std::move(out_);
  }

 private:
  bool v3() const { return header_.version >= 3.0; }
  std::size_t indent() const { return v3() ? 4 : 3; }

  Status parse_header() {
    const std::optional<std::string_view> first = reader_.next_line();
    if (!first) {
      if (reader_.read_error()) return reader_.error(*reader_.read_error());
      return Error{"empty file", reader_.path(), 0};
    }
    if (column(*first, 60, 20).find("RINEX VERSION / TYPE") == std::string_view::npos) {
      return reader_.error("not a RINEX file: first line has no 'RINEX VERSION / TYPE'");
    }
    const std::optional<double> version = parse_double(column(*first, 0, 9));
    if (!version) return reader_.error("bad RINEX version '" + std::string(trim(column(*first, 0, 9))) + "'");
    header_.version = *version;
    const std::string_view type = column(*first, 20, 1);
    header_.file_type = type.empty() ? ' ' : type[0];
    const std::string_view sys = column(*first, 40, 1);
    header_.system = sys.empty() ? ' ' : sys[0];
    if (header_.file_type != 'N' && header_.file_type != 'G') {
      return reader_.error(std::string("not a navigation file (file type '") + header_.file_type + "')");
    }
    if (header_.version < 2.0 || header_.version >= 4.0) {
      return reader_.error("unsupported RINEX version " + std::string(trim(column(*first, 0, 9))));
    }
    if (header_.version < 3.0 && header_.file_type == 'G') header_.system = 'R';
    if (header_.version < 3.0 && header_.file_type == 'N') header_.system = 'G';

    while (true) {
      const std::optional<std::string_view> line = reader_.next_line();
      if (!line) {
        if (reader_.read_error()) return reader_.error(*reader_.read_error());
        return reader_.error("missing END OF HEADER");
      }
      const std::string_view label = trim(column(*line, 60, 20));
      if (label == "END OF HEADER") return Ok{};
      Status s = parse_header_line(*line, label);
      if (!s.ok()) return s;
    }
  }

  Status parse_header_line(std::string_view line, std::string_view label) {
    if (label == "ION ALPHA" || label == "ION BETA") {
      std::array<double, 4> v{};
      for (int i = 0; i < 4; ++i) {
        const std::optional<double> x = parse_double(column(line, 2 + 12 * i, 12), 0.0);
        if (!x) return reader_.error("non-numeric field in " + std::string(label));
        v[i] = *x;
      }
      core::KlobucharParams& k = gps_klobuchar();
      (label == "ION ALPHA" ? k.alpha : k.beta) = v;
    } else if (label == "IONOSPHERIC CORR") {
      const std::string_view kind = trim(column(line, 0, 4));
      std::array<double, 4> v{};
      for (int i = 0; i < 4; ++i) {
        const std::optional<double> x = parse_double(column(line, 5 + 12 * i, 12), 0.0);
        if (!x) return reader_.error("non-numeric field in IONOSPHERIC CORR " + std::string(kind));
        v[i] = *x;
      }
      if (kind == "GPSA") gps_klobuchar().alpha = v;
      if (kind == "GPSB") gps_klobuchar().beta = v;
      if (kind == "BDSA") bds_klobuchar().alpha = v;
      if (kind == "BDSB") bds_klobuchar().beta = v;
    } else if (label == "LEAP SECONDS") {
      const std::optional<int> leap = parse_int(column(line, 0, 6));
      if (!leap) return reader_.error("non-numeric LEAP SECONDS");
      out_.nav.leap_seconds = *leap;
    }
    return Ok{};
  }

  core::KlobucharParams& gps_klobuchar() {
    if (!out_.nav.gps_klobuchar) out_.nav.gps_klobuchar = core::KlobucharParams{};
    return *out_.nav.gps_klobuchar;
  }
  core::KlobucharParams& bds_klobuchar() {
    if (!out_.nav.bds_klobuchar) out_.nav.bds_klobuchar = core::KlobucharParams{};
    return *out_.nav.bds_klobuchar;
  }

  /// True if `line` is a continuation ("broadcast orbit") line: blank indent.
  bool is_orbit_line(std::string_view line) const {
    if (line.size() <= indent()) return false;
    return trim(line.substr(0, indent())).empty() && !trim(line).empty();
  }

  Status parse_number(std::string_view line, std::size_t start, std::vector<double>& values) {
    const std::string_view field = column(line, start, 19);
    const std::optional<double> v = parse_double(field, 0.0);
    if (!v || !std::isfinite(*v)) {
      return reader_.error("non-numeric field '" + std::string(trim(field)) + "' at column " +
                           std::to_string(start + 1));
    }
    values.push_back(*v);
    return Ok{};
  }

  /// Reads `lines` orbit lines of four numbers each into `values`.
  Status read_orbit_lines(int lines, std::vector<double>& values) {
    for (int i = 0; i < lines; ++i) {
      const std::optional<std::string_view> line = reader_.next_line();
      if (!line) {
        if (reader_.read_error()) return reader_.error(*reader_.read_error());
        return reader_.error("truncated record: end of file after " + std::to_string(i + 1) + " of " +
                             std::to_string(lines + 1) + " lines");
      }
      if (!is_orbit_line(*line)) {
        return reader_.error("truncated record: expected broadcast orbit line " + std::to_string(i + 1) + " of " +
                             std::to_string(lines));
      }
      for (int k = 0; k < 4; ++k) {
        Status s = parse_number(*line, indent() + 19 * static_cast<std::size_t>(k), values);
        if (!s.ok()) return s;
      }
    }
    return Ok{};
  }

  /// Skips the orbit lines following a record of an unsupported system.
  void skip_record() {
    ++skipped_;
    while (true) {
      const std::optional<std::string_view> line = reader_.next_line();
      if (!line) return;
      if (!is_orbit_line(*line)) {
        reader_.unread_line();
        return;
      }
    }
  }

  Status parse_record(const std::string& line) {
    // Satellite.
    std::optional<core::SatelliteId> sat;
    char letter = header_.system;
    std::string_view sat_text;
    if (v3()) {
      sat_text = column(line, 0, 3);
      letter = sat_text.empty() ? ' ' : sat_text[0];
      if (letter == 'S' || letter == 'I') {
        skip_record();
        return Ok{};
      }
      sat = core::parse_satellite(sat_text);
    } else {
      sat_text = column(line, 0, 2);
      const std::optional<int> prn = parse_int(sat_text);
      if (prn && *prn >= 0 && *prn <= 255) {
        const auto system = core::constellation_from_letter(header_.system);
        if (system) sat = core::SatelliteId{*system, static_cast<std::uint8_t>(*prn)};
      }
    }
    if (!sat || !sat->valid()) return reader_.error("bad satellite number '" + std::string(sat_text) + "'");
    if (v3() && letter != core::system_letter(sat->system)) {
      return reader_.error("bad satellite number '" + std::string(sat_text) + "'");
    }

    // Epoch.
    CalendarTime epoch;
    std::size_t first_value;
    if (v3()) {
      const auto y = parse_int(column(line, 4, 4)), mo = parse_int(column(line, 9, 2)),
                 d = parse_int(column(line, 12, 2)), h = parse_int(column(line, 15, 2)),
                 mi = parse_int(column(line, 18, 2)), s = parse_int(column(line, 21, 2));
      if (!y || !mo || !d || !h || !mi || !s) return reader_.error("non-numeric field in the record epoch");
      epoch = CalendarTime{*y, *mo, *d, *h, *mi, double(*s)};
      first_value = 23;
    } else {
      const auto y = parse_int(column(line, 2, 3)), mo = parse_int(column(line, 5, 3)),
                 d = parse_int(column(line, 8, 3)), h = parse_int(column(line, 11, 3)),
                 mi = parse_int(column(line, 14, 3));
      const auto s = parse_double(column(line, 17, 5));
      if (!y || !mo || !d || !h || !mi || !s) return reader_.error("non-numeric field in the record epoch");
      epoch = CalendarTime{*y < 80 ? *y + 2000 : (*y < 100 ? *y + 1900 : *y), *mo, *d, *h, *mi, *s};
      first_value = 22;
    }
    if (!core::is_valid(epoch)) return reader_.error("invalid epoch " + core::format_calendar(epoch, 1));
    const int record_line = reader_.line_number();

    std::vector<double> v;
    for (int k = 0; k < 3; ++k) {
      Status s = parse_number(line, first_value + 19 * static_cast<std::size_t>(k), v);
      if (!s.ok()) return s;
    }
    if (sat->system == Constellation::Glonass) {
      Status s = read_orbit_lines(kGlonassOrbitLines, v);
      if (!s.ok()) return s;
      // RINEX 3.05 adds a fourth orbit line (status flags, group delay, URAI, health flags): accept and ignore it.
      const std::optional<std::string_view> extra = reader_.next_line();
      if (extra && !(v3() && is_orbit_line(*extra))) reader_.unread_line();
      return add_glonass(*sat, epoch, v, record_line);
    }
    Status s = read_orbit_lines(kKeplerOrbitLines, v);
    if (!s.ok()) return s;
    return add_kepler(*sat, epoch, v, record_line);
  }

  /// Integer-valued fields (IODE, health, codes, week, ...) must fit an int before they are converted.
  Status check_integers(const std::vector<double>& v, std::initializer_list<std::size_t> indices, int line) const {
    for (const std::size_t i : indices) {
      if (!(std::abs(v[i]) < 1e9)) {
        return Error{"integer field " + std::to_string(i + 1) + " out of range", reader_.path(), line};
      }
    }
    return Ok{};
  }

  Status add_kepler(core::SatelliteId sat, const CalendarTime& epoch, const std::vector<double>& v, int line) {
    Status ints = check_integers(v, {3, 20, 21, 24, 26, 28}, line);
    if (!ints.ok()) return ints;
    core::KeplerEphemeris e;
    e.sat = sat;
    const bool bds = sat.system == Constellation::BeiDou;
    // Clock reference time: GPST calendar for GPS/QZSS, GST (same second, same calendar) for Galileo, BDT for BeiDou.
    e.toc = core::calendar_to_gps(epoch);
    if (bds) e.toc = e.toc - core::kBdtMinusGpstS;
    e.af0_s = v[0];
    e.af1_sps = v[1];
    e.af2_sps2 = v[2];
    e.iode = static_cast<int>(v[3]);
    e.crs_m = v[4];
    e.delta_n_radps = v[5];
    e.m0_rad = v[6];
    e.cuc_rad = v[7];
    e.e = v[8];
    e.cus_rad = v[9];
    e.sqrt_a_sqrtm = v[10];
    e.toe_sow_s = v[11];
    e.cic_rad = v[12];
    e.omega0_rad = v[13];
    e.cis_rad = v[14];
    e.i0_rad = v[15];
    e.crc_m = v[16];
    e.omega_rad = v[17];
    e.omega_dot_radps = v[18];
    e.idot_radps = v[19];
    e.data_source = static_cast<int>(v[20]);
    const double week = v[21];
    e.accuracy_m = v[23];
    e.health = static_cast<int>(v[24]);
    e.tgd_s[0] = v[25];
    const double ttr_sow_s = v[27];
    if (sat.system == Constellation::Galileo || bds) {
      e.tgd_s[1] = v[26];
    } else {
      e.iodc = static_cast<int>(v[26]);
    }
    if (bds) {
      e.iodc = static_cast<int>(v[28]);  // AODC
    } else if (sat.system != Constellation::Galileo) {
      e.fit_interval_h = v[28];
    }
    if (week < 0.0 || week > 1.0e5 || e.toe_sow_s < 0.0 || e.toe_sow_s > kSecondsPerWeek) {
      return Error{"bad week number or toe in record", reader_.path(), line};
    }
    // toe from the record's week (GPS week; Galileo's RINEX week is aligned with GPS; BeiDou's is a BDT week). The
    // week may be of the transmission rather than of toe, or truncated: take the candidate nearest toc.
    const int w = static_cast<int>(week);
    GpsTime toe = bds ? core::bdt_to_gps(w, e.toe_sow_s) : GpsTime{w, e.toe_sow_s}.normalized();
    e.toe = nearest_by_period(toe, e.toc, kSecondsPerWeek);
    // Transmission time: seconds of the same week, possibly negative or beyond the week.
    GpsTime ttr = bds ? core::bdt_to_gps(w, 0.0) + ttr_sow_s : GpsTime{w, 0.0} + ttr_sow_s;
    e.transmission_time = std::abs(ttr - e.toe) < kSecondsPerWeek ? ttr : e.toe;
    out_.nav.kepler.push_back(e);
    return Ok{};
  }

  Status add_glonass(core::SatelliteId sat, const CalendarTime& epoch_utc, const std::vector<double>& v, int line) {
    Status ints = check_integers(v, {6, 10, 14}, line);
    if (!ints.ok()) return ints;
    core::GlonassEphemeris g;
    g.sat = sat;
    const int leap = out_.nav.leap_seconds.value_or(leaps_.gps_minus_utc_at_utc(epoch_utc));
    const GpsTime utc_as_gps = core::calendar_to_gps(epoch_utc);  // UTC instant on a GPST-like week count
    g.toe = utc_as_gps + leap;
    g.tau_n_s = v[0];  // RINEX "SV clock bias" = -TauN
    g.gamma_n = v[1];
    // Message frame time: seconds of the UTC week (RINEX 3) or of the UTC day (RINEX 2).
    const double period_s = v3() ? kSecondsPerWeek : kSecondsPerDay;
    const double start_offset_s = std::fmod(utc_as_gps.tow_s, period_s);
    const GpsTime tk_utc = nearest_by_period(utc_as_gps - start_offset_s + v[2], utc_as_gps, period_s);
    g.frame_time = tk_utc + leap;
    g.p_E_m = Eigen::Vector3d(v[3], v[7], v[11]) * 1e3;
    g.v_E_mps = Eigen::Vector3d(v[4], v[8], v[12]) * 1e3;
    g.a_E_mps2 = Eigen::Vector3d(v[5], v[9], v[13]) * 1e3;
    g.health = static_cast<int>(v[6]);
    g.frequency_channel = static_cast<int>(std::lround(v[10]));
    g.age_days = static_cast<int>(v[14]);
    if (g.frequency_channel < -7 || g.frequency_channel > 13) {
      return Error{"bad GLONASS frequency channel " + std::to_string(g.frequency_channel), reader_.path(), line};
    }
    out_.nav.glonass.push_back(g);
    return Ok{};
  }

  TextReader reader_;
  const core::LeapSecondTable& leaps_;
  Header header_;
  RinexNavFile out_;
  int skipped_ = 0;
};

// ---------------------------------------------------------------------------------------------------------------
// Writer.

std::string format_d19(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%19.12E", value);
  return buffer;
}

std::string header_line(const std::string& content, const std::string& label) {
  std::string line = content;
  line.resize(60, ' ');
  return line + label;
}

std::string iono_line(const char* kind, const std::array<double, 4>& v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%-4s %12.4E%12.4E%12.4E%12.4E", kind, v[0], v[1], v[2], v[3]);
  return header_line(buffer, "IONOSPHERIC CORR");
}

std::string epoch_line(core::SatelliteId sat, const CalendarTime& c, double a, double b, double d) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%s %04d %02d %02d %02d %02d %02d", sat.to_string().c_str(), c.year, c.month,
                c.day, c.hour, c.minute, static_cast<int>(std::lround(c.second)));
  return std::string(buffer) + format_d19(a) + format_d19(b) + format_d19(d);
}

std::string orbit_line(std::initializer_list<double> values) {
  std::string line = "    ";
  for (const double v : values) line += format_d19(v);
  return line;
}

/// Calendar of a GPST instant rounded to the whole second (RINEX 3 epochs have integer seconds).
CalendarTime whole_second_calendar(const GpsTime& t) {
  return core::gps_to_calendar(t + (std::round(t.tow_s) - t.tow_s));
}

void write_kepler(std::ostream& os, const core::KeplerEphemeris& e) {
  const bool bds = e.sat.system == Constellation::BeiDou;
  const bool gal = e.sat.system == Constellation::Galileo;
  const CalendarTime toc = whole_second_calendar(bds ? e.toc + core::kBdtMinusGpstS : e.toc);
  const int week = bds ? core::gps_to_bdt(e.toe).week : e.toe.week;
  const GpsTime week_start = bds ? core::bdt_to_gps(week, 0.0) : GpsTime{week, 0.0};
  const double ttr_s = e.transmission_time - week_start;
  os << epoch_line(e.sat, toc, e.af0_s, e.af1_sps, e.af2_sps2) << '\n';
  os << orbit_line({double(e.iode), e.crs_m, e.delta_n_radps, e.m0_rad}) << '\n';
  os << orbit_line({e.cuc_rad, e.e, e.cus_rad, e.sqrt_a_sqrtm}) << '\n';
  os << orbit_line({e.toe_sow_s, e.cic_rad, e.omega0_rad, e.cis_rad}) << '\n';
  os << orbit_line({e.i0_rad, e.crc_m, e.omega_rad, e.omega_dot_radps}) << '\n';
  os << orbit_line({e.idot_radps, double(e.data_source), double(week), 0.0}) << '\n';
  const double last = (gal || bds) ? e.tgd_s[1] : double(e.iodc);
  os << orbit_line({e.accuracy_m, double(e.health), e.tgd_s[0], last}) << '\n';
  if (bds) {
    os << orbit_line({ttr_s, double(e.iodc)}) << '\n';
  } else if (gal) {
    os << orbit_line({ttr_s}) << '\n';
  } else {
    os << orbit_line({ttr_s, e.fit_interval_h}) << '\n';
  }
}

void write_glonass(std::ostream& os, const core::GlonassEphemeris& g, int leap_s) {
  const GpsTime toe_utc = g.toe - double(leap_s);
  const GpsTime tk_utc = g.frame_time - double(leap_s);
  const double tk_sow_s = tk_utc - GpsTime{toe_utc.week, 0.0};
  os << epoch_line(g.sat, whole_second_calendar(toe_utc), g.tau_n_s, g.gamma_n, tk_sow_s) << '\n';
  const Eigen::Vector3d p_km = g.p_E_m * 1e-3, v_kmps = g.v_E_mps * 1e-3, a_kmps2 = g.a_E_mps2 * 1e-3;
  os << orbit_line({p_km.x(), v_kmps.x(), a_kmps2.x(), double(g.health)}) << '\n';
  os << orbit_line({p_km.y(), v_kmps.y(), a_kmps2.y(), double(g.frequency_channel)}) << '\n';
  os << orbit_line({p_km.z(), v_kmps.z(), a_kmps2.z(), double(g.age_days)}) << '\n';
}

}  // namespace

Result<RinexNavFile> read_rinex_nav(const std::string& path, const core::LeapSecondTable& leaps) {
  Result<TextReader> reader = TextReader::open(path);
  if (!reader.ok()) return reader.error();
  NavParser parser(std::move(reader).value(), leaps);
  return parser.parse();
}

Status write_rinex_nav(const std::string& path, const core::NavigationData& nav, const core::LeapSecondTable& leaps) {
  std::ofstream os(path);
  if (!os) return Error{"cannot open for writing", path, 0};
  int leap_s = nav.leap_seconds.value_or(0);
  if (!nav.leap_seconds) {
    GpsTime t{};
    if (!nav.kepler.empty()) t = nav.kepler.front().toe;
    if (!nav.glonass.empty()) t = nav.glonass.front().toe;
    leap_s = leaps.gps_minus_utc_at_gps(t);
  }
  os << header_line("     3.04           N: GNSS NAV DATA    M: MIXED", "RINEX VERSION / TYPE") << '\n';
  os << header_line("canyon", "PGM / RUN BY / DATE") << '\n';
  if (nav.gps_klobuchar) {
    os << iono_line("GPSA", nav.gps_klobuchar->alpha) << '\n' << iono_line("GPSB", nav.gps_klobuchar->beta) << '\n';
  }
  if (nav.bds_klobuchar) {
    os << iono_line("BDSA", nav.bds_klobuchar->alpha) << '\n' << iono_line("BDSB", nav.bds_klobuchar->beta) << '\n';
  }
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "%6d", leap_s);
  os << header_line(buffer, "LEAP SECONDS") << '\n';
  os << header_line("", "END OF HEADER") << '\n';
  for (const core::KeplerEphemeris& e : nav.kepler) write_kepler(os, e);
  for (const core::GlonassEphemeris& g : nav.glonass) write_glonass(os, g, leap_s);
  os.flush();
  if (!os) return Error{"write failed", path, 0};
  return Ok{};
}

}  // namespace canyon::io
