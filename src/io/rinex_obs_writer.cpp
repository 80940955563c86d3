// RINEX 3.04 observation writer.
//
// Writes a header (version, program, marker, receiver and antenna, approximate position, antenna offsets,
// observation types per system, phase shifts, GLONASS slots, interval, time of first observation, leap seconds)
// and one '>' record per epoch with F14.3 values, the LLI digit on carrier phases and a signal strength digit
// derived from the SNR. Time tags are written in GPST. Observation types are those of the header, extended by any
// signal observable the epochs carry that the header does not list, so whatever the reader read can be written.

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <string_view>

#include "canyon/io/rinex_obs.hpp"

namespace canyon::io {

namespace {

using core::Constellation;

constexpr std::size_t kTypesPerLine = 13;
constexpr std::size_t kSlotsPerLine = 8;
constexpr double kMaxF14Value = 9999999999.999;  // largest magnitude F14.3 holds
constexpr double kMinF14Value = -999999999.999;
constexpr std::array<char, 4> kKinds = {'C', 'L', 'D', 'S'};

/// Appends `content` padded to 60 columns and the label.
void add_header_line(std::string& out, std::string_view content, std::string_view label) {
  std::string line(content.substr(0, std::min<std::size_t>(content.size(), 60)));
  line.resize(60, ' ');
  out += line;
  out += label;
  out += '\n';
}

template <typename... Args>
std::string format(const char* fmt, Args... args) {
  char buffer[256];
  const int n = std::snprintf(buffer, sizeof buffer, fmt, args...);
  return std::string(buffer, n < 0 ? 0 : std::min<std::size_t>(static_cast<std::size_t>(n), sizeof buffer - 1));
}

/// Value of one observable of a signal, NaN if absent.
double observable(const core::SignalObs& s, char kind) {
  switch (kind) {
    case 'C': return s.pseudorange_m;
    case 'L': return s.carrier_phase_cyc;
    case 'D': return s.doppler_hz;
    case 'S': return s.snr_dbhz;
    default: return core::kNoValue;
  }
}

/// RINEX signal strength indicator 1-9 from an SNR (dB-Hz), ' ' if unknown.
char strength_digit(double snr_dbhz) {
  if (!core::has_value(snr_dbhz)) return ' ';
  const int ssi = std::clamp(static_cast<int>(std::floor(snr_dbhz / 6.0)), 1, 9);
  return static_cast<char>('0' + ssi);
}

struct Column {
  char kind = 0;  // 0: a type canyon cannot fill (written blank)
  core::SignalCode signal;
};

using TypeLists = std::map<Constellation, std::vector<std::string>>;

/// Header types, extended by every observable present in the epochs.
TypeLists collect_types(const RinexObsHeader& header, const std::vector<core::ObsEpoch>& epochs) {
  TypeLists types = header.obs_types;
  for (auto it = types.begin(); it != types.end();) {
    it = it->second.empty() ? types.erase(it) : std::next(it);
  }
  for (const core::ObsEpoch& epoch : epochs) {
    for (const core::SatelliteObs& sat : epoch.sats) {
      std::vector<std::string>& codes = types[sat.sat.system];
      for (const core::SignalObs& s : sat.signals) {
        for (const char kind : kKinds) {
          if (!core::has_value(observable(s, kind))) continue;
          const std::string code{kind, s.code.band, s.code.attribute};
          if (std::find(codes.begin(), codes.end(), code) == codes.end()) codes.push_back(code);
        }
      }
    }
  }
  return types;
}

std::string calendar_fields(const core::GpsTime& t, const char* fmt) {
  // Round to 0.1 us first so that 59.99999999 s never prints as 60.0000000.
  const core::GpsTime n = t.normalized();
  const auto ticks = static_cast<long long>(std::llround(n.tow_s * 1e7));
  const auto whole_s = ticks / 10000000;
  const core::CalendarTime c = core::gps_to_calendar(core::GpsTime{n.week, static_cast<double>(whole_s)});
  const double second = std::round(c.second) + static_cast<double>(ticks % 10000000) * 1e-7;
  return format(fmt, c.year, c.month, c.day, c.hour, c.minute, second);
}

void write_obs_types(std::string& out, const TypeLists& types) {
  for (const auto& [system, codes] : types) {
    std::string line = format("%c  %3d", core::system_letter(system), static_cast<int>(codes.size()));
    for (std::size_t k = 0; k < codes.size(); ++k) {
      if (k > 0 && k % kTypesPerLine == 0) {
        add_header_line(out, line, "SYS / # / OBS TYPES");
        line = "      ";
      }
      line += format(" %-3s", codes[k].c_str());
    }
    add_header_line(out, line, "SYS / # / OBS TYPES");
  }
}

void write_glonass_slots(std::string& out, const std::vector<std::pair<int, int>>& slots) {
  if (slots.empty()) return;
  std::string line = format("%3d ", static_cast<int>(slots.size()));
  for (std::size_t k = 0; k < slots.size(); ++k) {
    if (k > 0 && k % kSlotsPerLine == 0) {
      add_header_line(out, line, "GLONASS SLOT / FRQ #");
      line = "    ";
    }
    line += format("R%02d %2d ", slots[k].first, slots[k].second);
  }
  add_header_line(out, line, "GLONASS SLOT / FRQ #");
}

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y%m%d %H%M%S UTC", &utc);
  return text;
}

void write_header(std::string& out, const RinexObsHeader& header, const TypeLists& types,
                  const std::vector<core::ObsEpoch>& epochs) {
  const char system = types.size() == 1 ? core::system_letter(types.begin()->first) : 'M';
  add_header_line(out, format("%9.2f           %-20s%-20c", 3.04, "OBSERVATION DATA", system), "RINEX VERSION / TYPE");
  const std::string date = header.program_date.empty() ? utc_now() : header.program_date.substr(0, 20);
  add_header_line(out, format("%-20s%-20s%-20s", "canyon", "", date.c_str()), "PGM / RUN BY / DATE");
  const core::ReceiverInfo& rx = header.receiver;
  add_header_line(out, rx.marker_name, "MARKER NAME");
  add_header_line(out, format("%-20s%-20.20s%-20s", "", rx.receiver_type.c_str(), ""), "REC # / TYPE / VERS");
  add_header_line(out, format("%-20s%-20.20s", "", rx.antenna_type.c_str()), "ANT # / TYPE");
  const Eigen::Vector3d p = rx.approx_position_E_m.value_or(Eigen::Vector3d::Zero());
  add_header_line(out, format("%14.4f%14.4f%14.4f", p.x(), p.y(), p.z()), "APPROX POSITION XYZ");
  const Eigen::Vector3d& d = rx.antenna_delta_hen_m;
  add_header_line(out, format("%14.4f%14.4f%14.4f", d.x(), d.y(), d.z()), "ANTENNA: DELTA H/E/N");
  write_obs_types(out, types);
  add_header_line(out, "DBHZ", "SIGNAL STRENGTH UNIT");
  for (const auto& shift : rx.phase_shifts) {
    add_header_line(out,
                    format("%c L%c%c %8.5f", core::system_letter(shift.system), shift.code.band, shift.code.attribute,
                           shift.shift_cyc),
                    "SYS / PHASE SHIFT");
  }
  write_glonass_slots(out, rx.glonass_slot_channels);
  if (header.interval_s > 0.0) add_header_line(out, format("%10.3f", header.interval_s), "INTERVAL");
  std::optional<core::GpsTime> first = header.first_obs;
  if (!first && !epochs.empty()) first = epochs.front().time;
  if (first) {
    add_header_line(out, calendar_fields(*first, "%6d%6d%6d%6d%6d%13.7f") + "     GPS", "TIME OF FIRST OBS");
  }
  if (header.leap_seconds) add_header_line(out, format("%6d", *header.leap_seconds), "LEAP SECONDS");
  add_header_line(out, "", "END OF HEADER");
}

/// Column plan per system for the records.
std::map<Constellation, std::vector<Column>> plan_columns(const TypeLists& types) {
  std::map<Constellation, std::vector<Column>> plan;
  for (const auto& [system, codes] : types) {
    std::vector<Column>& columns = plan[system];
    for (const std::string& code : codes) {
      Column c;
      const auto signal = code.size() == 3 ? core::parse_signal(std::string_view(code).substr(1)) : std::nullopt;
      if (signal && std::find(kKinds.begin(), kKinds.end(), code[0]) != kKinds.end()) {
        c.kind = code[0];
        c.signal = *signal;
      }
      columns.push_back(c);
    }
  }
  return plan;
}

/// Appends one satellite record; Error if a value does not fit F14.3.
Status write_satellite(std::string& out, const core::SatelliteObs& sat, const std::vector<Column>& columns,
                       const core::ObsEpoch& epoch) {
  const std::size_t start = out.size();
  out += sat.sat.to_string();
  for (const Column& c : columns) {
    const core::SignalObs* s = c.kind != 0 ? sat.find(c.signal) : nullptr;
    const double value = s != nullptr ? observable(*s, c.kind) : core::kNoValue;
    if (s == nullptr || !core::has_value(value)) {
      out.append(16, ' ');
      continue;
    }
    if (value > kMaxF14Value || value < kMinF14Value) {
      return Error{"value " + format("%.3f", value) + " of " + sat.sat.to_string() + " " + c.kind +
                       c.signal.to_string() + " at " + calendar_fields(epoch.time, "%04d-%02d-%02d %02d:%02d:%010.7f") +
                       " does not fit RINEX F14.3",
                   "", 0};
    }
    out += format("%14.3f", value);
    const bool lli = c.kind == 'L' && s->lli > 0 && s->lli <= 9;
    out += lli ? static_cast<char>('0' + s->lli) : ' ';
    out += c.kind == 'S' ? ' ' : strength_digit(s->snr_dbhz);
  }
  const std::size_t end = out.find_last_not_of(' ');
  out.resize(std::max(end == std::string::npos ? start : end + 1, start + 3));
  out += '\n';
  return Ok{};
}

Status write_epoch(std::string& out, const core::ObsEpoch& epoch,
                   const std::map<Constellation, std::vector<Column>>& plan) {
  const int flag = static_cast<int>(epoch.flag);
  const bool event = flag >= 2 && flag <= 5;  // canyon keeps no event records: written without any
  const int count = event ? 0 : static_cast<int>(epoch.sats.size());
  out += calendar_fields(epoch.time, "> %04d %02d %02d %02d %02d%11.7f");
  out += format("  %1d%3d", flag, count);
  if (core::has_value(epoch.receiver_clock_offset_s)) out += format("      %15.12f", epoch.receiver_clock_offset_s);
  out += '\n';
  if (event) return Ok{};
  for (const core::SatelliteObs& sat : epoch.sats) {
    if (Status s = write_satellite(out, sat, plan.at(sat.sat.system), epoch); !s.ok()) return s;
  }
  return Ok{};
}

}  // namespace

Status write_rinex_obs(const std::string& path, const RinexObsHeader& header,
                       const std::vector<core::ObsEpoch>& epochs) {
  const TypeLists types = collect_types(header, epochs);
  const auto plan = plan_columns(types);
  std::string out;
  write_header(out, header, types, epochs);
  for (const core::ObsEpoch& epoch : epochs) {
    if (Status s = write_epoch(out, epoch, plan); !s.ok()) return Error{s.error().message, path, 0};
  }
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) return Error{std::string("cannot write file: ") + std::strerror(errno), path, 0};
  const bool written = std::fwrite(out.data(), 1, out.size(), file) == out.size();
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed) return Error{std::string("write failed: ") + std::strerror(errno), path, 0};
  return Ok{};
}

}  // namespace canyon::io
