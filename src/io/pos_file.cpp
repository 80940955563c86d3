// RTKLIB-compatible .pos solution files: writer and reader (format in pos_file.hpp).

#include "canyon/io/pos_file.hpp"

#include <cmath>
#include <sstream>

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

Result<std::vector<core::Solution>> read_pos_file(const std::string& path) {
  auto reader = TextReader::open(path);
  if (!reader) return reader.error();
  std::vector<core::Solution> out;
  while (auto line = reader->next_line()) {
    const std::string_view text = trim(*line);
    if (text.empty() || text.front() == '%') continue;
    std::istringstream in{std::string(text)};
    core::Solution s;
    std::string first;
    in >> first;
    if (first.find('/') != std::string::npos) {
      std::string clock;
      in >> clock;
      core::CalendarTime c;
      if (std::sscanf(first.c_str(), "%d/%d/%d", &c.year, &c.month, &c.day) != 3 ||
          std::sscanf(clock.c_str(), "%d:%d:%lf", &c.hour, &c.minute, &c.second) != 3 || !core::is_valid(c)) {
        std::string message = "bad date/time '";
        message.append(first).append(" ").append(clock).append("'");
        return reader->error(std::move(message));
      }
      s.time = core::calendar_to_gps(c);
    } else {
      const auto week = parse_int(first);
      double tow = 0.0;
      if (!week || !(in >> tow)) return reader->error("bad GPST week/time of week");
      s.time = core::GpsTime{*week, tow};
    }
    double a = 0, b = 0, c = 0;
    int q = 0;
    double sd[6] = {0, 0, 0, 0, 0, 0};
    if (!(in >> a >> b >> c >> q >> s.num_satellites)) return reader->error("bad position fields");
    for (double& v : sd) in >> v;  // optional in some files
    in >> s.age_s >> s.ratio;
    s.status = static_cast<core::SolutionStatus>(q);
    const bool llh = std::abs(a) <= 90.0 && std::abs(b) <= 360.0 && std::abs(c) < 1e5;
    if (llh) {
      const core::Geodetic g{a * core::kDegToRad, b * core::kDegToRad, c};
      s.p_E_m = core::geodetic_to_ecef(g);
      Eigen::Matrix3d P_N;
      P_N << sd[1] * sd[1], signed_square(sd[3]), signed_square(sd[4]), signed_square(sd[3]), sd[0] * sd[0],
          signed_square(sd[5]), signed_square(sd[4]), signed_square(sd[5]), sd[2] * sd[2];
      const Eigen::Matrix3d R_NE = core::rotation_enu_from_ecef(g);
      s.P_E_m2 = R_NE.transpose() * P_N * R_NE;
    } else {
      s.p_E_m = Eigen::Vector3d(a, b, c);
      s.P_E_m2 << sd[0] * sd[0], signed_square(sd[3]), signed_square(sd[5]), signed_square(sd[3]), sd[1] * sd[1],
          signed_square(sd[4]), signed_square(sd[5]), signed_square(sd[4]), sd[2] * sd[2];
    }
    out.push_back(s);
  }
  if (reader->read_error()) return reader->error(*reader->read_error());
  return out;
}

}  // namespace canyon::io
