#include "canyon/io/nmea.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <vector>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/io/number_format.hpp"

namespace canyon::io {
namespace {

constexpr long long kMinuteDecimalsScale = 10'000'000;  // minutes with 7 decimals
constexpr int kMaxStationId = 1023;

/// |angle| as whole degrees and minutes in units of 1e-7 minute, rounded once so that minutes never print as 60.
struct DegreesMinutes {
  long long degrees = 0;
  long long minutes_e7 = 0;
};
DegreesMinutes to_degrees_minutes(double angle_deg) {
  const auto total_e7 = static_cast<long long>(std::llround(std::abs(angle_deg) * 60.0 * kMinuteDecimalsScale));
  return {total_e7 / (60 * kMinuteDecimalsScale), total_e7 % (60 * kMinuteDecimalsScale)};
}

void append_zero_padded(std::string& out, long long value, int digits) {
  std::string text = std::to_string(value);
  if (static_cast<int>(text.size()) < digits) out.append(static_cast<std::size_t>(digits) - text.size(), '0');
  out += text;
}

void append_angle(std::string& out, double angle_deg, int degree_digits, char positive, char negative) {
  const DegreesMinutes dm = to_degrees_minutes(angle_deg);
  append_zero_padded(out, dm.degrees, degree_digits);
  append_zero_padded(out, dm.minutes_e7 / kMinuteDecimalsScale, 2);
  out += '.';
  append_zero_padded(out, dm.minutes_e7 % kMinuteDecimalsScale, 7);
  out += ',';
  out += angle_deg < 0.0 && (dm.degrees != 0 || dm.minutes_e7 != 0) ? negative : positive;
}

/// hhmmss.ss of the UTC time of day, rounded to 0.01 s on the GPST side so that a carry reaches the minutes.
void append_utc_time(std::string& out, const core::GpsTime& time, const core::LeapSecondTable& leaps) {
  const core::GpsTime rounded{time.week, std::round(time.tow_s * 100.0) / 100.0};
  const core::CalendarTime utc = core::gps_to_utc(rounded.normalized(), leaps);
  const auto centiseconds = static_cast<long long>(std::llround(utc.second * 100.0));
  append_zero_padded(out, utc.hour, 2);
  append_zero_padded(out, utc.minute, 2);
  append_zero_padded(out, centiseconds / 100, 2);
  out += '.';
  append_zero_padded(out, centiseconds % 100, 2);
}

void append_checksum(std::string& sentence) {
  const std::uint8_t sum = nmea_checksum(std::string_view(sentence).substr(1));
  static constexpr char kHex[] = "0123456789ABCDEF";
  sentence += '*';
  sentence += kHex[sum >> 4];
  sentence += kHex[sum & 0x0F];
}

bool is_differential(core::SolutionStatus status) {
  return status == core::SolutionStatus::Fixed || status == core::SolutionStatus::Float;
}

std::vector<std::string_view> split_fields(std::string_view body) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = body.find(',', start);
    if (comma == std::string_view::npos) {
      fields.push_back(body.substr(start));
      return fields;
    }
    fields.push_back(body.substr(start, comma - start));
    start = comma + 1;
  }
}

std::optional<double> to_double(std::string_view text) {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::optional<int> to_int(std::string_view text) {
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::optional<int> hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return std::nullopt;
}

/// Optional number field: empty -> nullopt, malformed -> Error naming the field.
Result<std::optional<double>> optional_number(std::string_view field, const char* name) {
  if (field.empty()) return std::optional<double>{};
  const auto value = to_double(field);
  if (!value) return Error{std::string("GGA: bad ") + name + " '" + std::string(field) + "'"};
  return std::optional<double>{*value};
}

/// ddmm.mmm (degree_digits = 2) or dddmm.mmm (3) with hemisphere -> signed degrees; both empty -> nullopt.
Result<std::optional<double>> parse_angle(std::string_view value, std::string_view hemisphere, int degree_digits,
                                          char positive, char negative, const char* name) {
  if (value.empty() && hemisphere.empty()) return std::optional<double>{};
  const auto bad = [&] { return Error{std::string("GGA: bad ") + name + " '" + std::string(value) + "'"}; };
  if (value.size() < static_cast<std::size_t>(degree_digits) + 2) return bad();
  const auto degrees = to_int(value.substr(0, static_cast<std::size_t>(degree_digits)));
  const auto minutes = to_double(value.substr(static_cast<std::size_t>(degree_digits)));
  if (!degrees || !minutes || *minutes < 0.0 || *minutes >= 60.0) return bad();
  double angle_deg = *degrees + *minutes / 60.0;
  if (hemisphere.size() != 1 || (hemisphere[0] != positive && hemisphere[0] != negative)) {
    return Error{std::string("GGA: bad ") + name + " hemisphere '" + std::string(hemisphere) + "'"};
  }
  if (hemisphere[0] == negative) angle_deg = -angle_deg;
  return std::optional<double>{angle_deg};
}

}  // namespace

std::uint8_t nmea_checksum(std::string_view body) {
  std::uint8_t sum = 0;
  for (const char c : body) sum ^= static_cast<std::uint8_t>(c);
  return sum;
}

int gga_quality(core::SolutionStatus status) {
  switch (status) {
    case core::SolutionStatus::Fixed: return 4;
    case core::SolutionStatus::Float: return 5;
    case core::SolutionStatus::Single: return 1;
    case core::SolutionStatus::VioFillIn: return 6;
    default: return 0;
  }
}

std::string format_gga(const core::Solution& solution, const core::LeapSecondTable& leaps, const GgaOptions& options) {
  std::string out = "$GPGGA,";
  out.reserve(96);
  append_utc_time(out, solution.time, leaps);
  out += ',';
  const int quality = gga_quality(solution.status);
  if (quality == 0) {
    out += ",,,,0,00,,,,,,,";
    append_checksum(out);
    return out;
  }
  const core::Geodetic g = core::ecef_to_geodetic(solution.p_E_m);
  append_angle(out, g.lat_rad * core::kRadToDeg, 2, 'N', 'S');
  out += ',';
  append_angle(out, g.lon_rad * core::kRadToDeg, 3, 'E', 'W');
  out += ',';
  append_int(out, quality, 1);
  out += ',';
  append_zero_padded(out, std::clamp(solution.num_satellites, 0, 99), 2);
  out += ',';
  if (options.hdop) append_fixed(out, *options.hdop, 1, 1);
  out += ',';
  append_fixed(out, g.height_m, 1, 3);
  out += ",M,0.000,M,";
  const bool differential = is_differential(solution.status);
  if (differential) append_fixed(out, solution.age_s, 1, 1);
  out += ',';
  if (differential && options.station_id && *options.station_id >= 0 && *options.station_id <= kMaxStationId) {
    append_zero_padded(out, *options.station_id, 4);
  }
  append_checksum(out);
  return out;
}

Result<GgaSentence> parse_gga(std::string_view sentence) {
  while (!sentence.empty() && (sentence.back() == '\n' || sentence.back() == '\r')) sentence.remove_suffix(1);
  if (sentence.empty() || sentence.front() != '$') return Error{"GGA: sentence does not start with '$'"};
  const std::size_t star = sentence.rfind('*');
  if (star == std::string_view::npos || star + 3 != sentence.size()) {
    return Error{"GGA: missing checksum ('*' and two hex digits at the end)"};
  }
  const std::string_view body = sentence.substr(1, star - 1);
  const auto high = hex_digit(sentence[star + 1]);
  const auto low = hex_digit(sentence[star + 2]);
  if (!high || !low) return Error{"GGA: checksum is not hexadecimal"};
  const int expected = nmea_checksum(body);
  if (*high * 16 + *low != expected) {
    char message[64];
    std::snprintf(message, sizeof message, "GGA: checksum %c%c, computed %02X", sentence[star + 1], sentence[star + 2],
                  expected);
    return Error{message};
  }
  const auto f = split_fields(body);
  if (f[0].size() != 5 || f[0].substr(2) != "GGA") return Error{"GGA: not a GGA sentence '" + std::string(f[0]) + "'"};
  if (f.size() != 15) return Error{"GGA: " + std::to_string(f.size()) + " fields, expected 15"};

  GgaSentence out;
  out.talker = std::string(f[0].substr(0, 2));
  if (f[1].size() < 6) return Error{"GGA: bad UTC time '" + std::string(f[1]) + "'"};
  const auto hours = to_int(f[1].substr(0, 2));
  const auto minutes = to_int(f[1].substr(2, 2));
  const auto seconds = to_double(f[1].substr(4));
  if (!hours || !minutes || !seconds || *hours > 23 || *minutes > 59 || *seconds >= 61.0) {
    return Error{"GGA: bad UTC time '" + std::string(f[1]) + "'"};
  }
  out.utc_seconds_of_day = *hours * 3600.0 + *minutes * 60.0 + *seconds;
  auto lat = parse_angle(f[2], f[3], 2, 'N', 'S', "latitude");
  if (!lat) return lat.error();
  auto lon = parse_angle(f[4], f[5], 3, 'E', 'W', "longitude");
  if (!lon) return lon.error();
  out.lat_deg = *lat;
  out.lon_deg = *lon;
  const auto quality = to_int(f[6]);
  if (!quality || *quality < 0 || *quality > 8) return Error{"GGA: bad fix quality '" + std::string(f[6]) + "'"};
  out.quality = *quality;
  const auto satellites = f[7].empty() ? std::optional<int>(0) : to_int(f[7]);
  if (!satellites || *satellites < 0) return Error{"GGA: bad number of satellites '" + std::string(f[7]) + "'"};
  out.num_satellites = *satellites;
  auto hdop = optional_number(f[8], "HDOP");
  if (!hdop) return hdop.error();
  out.hdop = *hdop;
  auto altitude = optional_number(f[9], "altitude");
  if (!altitude) return altitude.error();
  out.altitude_m = *altitude;
  if (!f[10].empty() && f[10] != "M") return Error{"GGA: altitude unit '" + std::string(f[10]) + "' is not M"};
  auto separation = optional_number(f[11], "geoid separation");
  if (!separation) return separation.error();
  out.geoid_separation_m = *separation;
  if (!f[12].empty() && f[12] != "M") return Error{"GGA: separation unit '" + std::string(f[12]) + "' is not M"};
  auto age = optional_number(f[13], "age of corrections");
  if (!age) return age.error();
  out.age_s = *age;
  if (!f[14].empty()) {
    const auto station = to_int(f[14]);
    if (!station || *station < 0 || *station > kMaxStationId) {
      return Error{"GGA: bad station id '" + std::string(f[14]) + "'"};
    }
    out.station_id = *station;
  }
  return out;
}

Result<NmeaWriter> NmeaWriter::create(const std::string& path, core::LeapSecondTable leaps, GgaOptions options) {
  auto file = TextFileWriter::create(path, "NMEA file");
  if (!file) return file.error();
  return NmeaWriter(std::move(*file), std::move(leaps), options);
}

Status NmeaWriter::write(const core::Solution& solution, std::optional<double> hdop) {
  GgaOptions options = options_;
  if (hdop) options.hdop = hdop;
  return file_.write_line(format_gga(solution, leaps_, options), "\r\n");  // NMEA 0183 ends sentences in CR LF
}

}  // namespace canyon::io
