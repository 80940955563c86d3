#include "canyon/core/satellite.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cstdio>

#include "canyon/core/constants.hpp"

namespace canyon::core {
namespace {

constexpr std::array<int, kNumConstellations> kMaxPrn = {32, 27, 36, 63, 10};

int first_index(Constellation c) {
  int index = 0;
  for (int s = 0; s < static_cast<int>(c); ++s) {
    index += kMaxPrn[static_cast<std::size_t>(s)];
  }
  return index;
}

}  // namespace

char system_letter(Constellation c) {
  switch (c) {
    case Constellation::Gps: return 'G';
    case Constellation::Glonass: return 'R';
    case Constellation::Galileo: return 'E';
    case Constellation::BeiDou: return 'C';
    case Constellation::Qzss: return 'J';
  }
  return '?';
}

std::optional<Constellation> constellation_from_letter(char letter) {
  switch (letter) {
    case 'G':
    case ' ': return Constellation::Gps;
    case 'R': return Constellation::Glonass;
    case 'E': return Constellation::Galileo;
    case 'C': return Constellation::BeiDou;
    case 'J': return Constellation::Qzss;
    default: return std::nullopt;
  }
}

std::string_view constellation_name(Constellation c) {
  switch (c) {
    case Constellation::Gps: return "GPS";
    case Constellation::Glonass: return "GLONASS";
    case Constellation::Galileo: return "Galileo";
    case Constellation::BeiDou: return "BeiDou";
    case Constellation::Qzss: return "QZSS";
  }
  return "?";
}

int max_prn(Constellation c) {
  return kMaxPrn[static_cast<std::size_t>(c)];
}

std::string SatelliteId::to_string() const {
  char buffer[8];
  std::snprintf(buffer, sizeof buffer, "%c%02d", system_letter(system), static_cast<int>(prn));
  return buffer;
}

int SatelliteId::index() const {
  return first_index(system) + prn - 1;
}

SatelliteId satellite_from_index(int index) {
  for (int s = 0; s < kNumConstellations; ++s) {
    const auto c = static_cast<Constellation>(s);
    if (index < max_prn(c)) {
      return SatelliteId{c, static_cast<std::uint8_t>(index + 1)};
    }
    index -= max_prn(c);
  }
  return SatelliteId{};
}

std::optional<SatelliteId> parse_satellite(std::string_view text) {
  while (!text.empty() && text.back() == ' ') {
    text.remove_suffix(1);
  }
  if (text.empty()) {
    return std::nullopt;
  }
  Constellation system = Constellation::Gps;
  if (!std::isdigit(static_cast<unsigned char>(text.front()))) {
    const auto c = constellation_from_letter(text.front());
    if (!c) {
      return std::nullopt;
    }
    system = *c;
    text.remove_prefix(1);
  }
  while (!text.empty() && text.front() == ' ') {
    text.remove_prefix(1);
  }
  int number = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), number);
  if (ec != std::errc{} || end != text.data() + text.size()) {
    return std::nullopt;
  }
  if (system == Constellation::Qzss && number > 192) {
    number -= 192;  // QZSS PRN 193.. written as a PRN rather than J01..
  }
  SatelliteId sat{system, static_cast<std::uint8_t>(number < 0 || number > 255 ? 0 : number)};
  if (!sat.valid()) {
    return std::nullopt;
  }
  return sat;
}

std::optional<SignalCode> parse_signal(std::string_view text) {
  if (text.size() != 2 || !std::isdigit(static_cast<unsigned char>(text[0])) ||
      !std::isalpha(static_cast<unsigned char>(text[1]))) {
    return std::nullopt;
  }
  return SignalCode{text[0], text[1]};
}

std::optional<double> carrier_frequency_hz(Constellation system, SignalCode signal, int glonass_channel) {
  constexpr double kMhz = 1e6;
  switch (system) {
    case Constellation::Gps:
      switch (signal.band) {
        case '1': return 1575.42 * kMhz;
        case '2': return 1227.60 * kMhz;
        case '5': return 1176.45 * kMhz;
        default: return std::nullopt;
      }
    case Constellation::Qzss:
      switch (signal.band) {
        case '1': return 1575.42 * kMhz;
        case '2': return 1227.60 * kMhz;
        case '5': return 1176.45 * kMhz;
        case '6': return 1278.75 * kMhz;
        default: return std::nullopt;
      }
    case Constellation::Galileo:
      switch (signal.band) {
        case '1': return 1575.42 * kMhz;
        case '5': return 1176.45 * kMhz;
        case '6': return 1278.75 * kMhz;
        case '7': return 1207.14 * kMhz;
        case '8': return 1191.795 * kMhz;
        default: return std::nullopt;
      }
    case Constellation::BeiDou:
      switch (signal.band) {
        case '1': return 1575.42 * kMhz;   // B1C (RINEX 3.04); RINEX 3.02 "1" is remapped to '2' by the reader
        case '2': return 1561.098 * kMhz;  // B1I
        case '5': return 1176.45 * kMhz;   // B2a
        case '6': return 1268.52 * kMhz;   // B3I
        case '7': return 1207.14 * kMhz;   // B2I / B2b
        case '8': return 1191.795 * kMhz;  // B2a+b
        default: return std::nullopt;
      }
    case Constellation::Glonass:
      switch (signal.band) {
        case '1':
          if (glonass_channel < -7 || glonass_channel > 6) return std::nullopt;
          return 1602.0 * kMhz + glonass_channel * 0.5625 * kMhz;
        case '2':
          if (glonass_channel < -7 || glonass_channel > 6) return std::nullopt;
          return 1246.0 * kMhz + glonass_channel * 0.4375 * kMhz;
        case '3': return 1202.025 * kMhz;
        case '4': return 1600.995 * kMhz;
        case '6': return 1248.06 * kMhz;
        default: return std::nullopt;
      }
  }
  return std::nullopt;
}

std::optional<double> wavelength_m(Constellation system, SignalCode signal, int glonass_channel) {
  const auto f = carrier_frequency_hz(system, signal, glonass_channel);
  if (!f) {
    return std::nullopt;
  }
  return kSpeedOfLightMps / *f;
}

std::optional<int> frequency_rank(Constellation system, char band) {
  switch (system) {
    case Constellation::Gps:
    case Constellation::Qzss:
      switch (band) {
        case '1': return 0;
        case '2': return 1;
        case '5': return 2;
        case '6': return system == Constellation::Qzss ? std::optional<int>(3) : std::nullopt;
        default: return std::nullopt;
      }
    case Constellation::Glonass:
      switch (band) {
        case '1':
        case '4': return 0;
        case '2':
        case '6': return 1;
        case '3': return 2;
        default: return std::nullopt;
      }
    case Constellation::Galileo:
      switch (band) {
        case '1': return 0;
        case '7': return 1;
        case '5': return 2;
        case '6': return 3;
        case '8': return 4;
        default: return std::nullopt;
      }
    case Constellation::BeiDou:
      switch (band) {
        case '2': return 0;
        case '7': return 1;
        case '6': return 2;
        case '1': return 3;
        case '5': return 4;
        case '8': return 5;
        default: return std::nullopt;
      }
  }
  return std::nullopt;
}

}  // namespace canyon::core

namespace canyon::core {

bool ConstellationFlags::uses(Constellation c) const {
  switch (c) {
    case Constellation::Gps: return use_gps;
    case Constellation::Glonass: return use_glonass;
    case Constellation::Galileo: return use_galileo;
    case Constellation::BeiDou: return use_beidou;
    case Constellation::Qzss: return use_qzss;
  }
  return false;
}

std::vector<std::string> ConstellationFlags::letters() const {
  std::vector<std::string> out;
  for (int s = 0; s < kNumConstellations; ++s) {
    const auto c = static_cast<Constellation>(s);
    if (uses(c)) out.emplace_back(1, system_letter(c));
  }
  return out;
}

bool ConstellationFlags::set_from_letters(const std::vector<std::string>& letters, std::string* bad_letter) {
  ConstellationFlags flags{false, false, false, false, false};
  for (const std::string& l : letters) {
    const auto c = l.size() == 1 && l[0] != ' ' ? constellation_from_letter(l[0]) : std::nullopt;
    if (!c) {
      if (bad_letter != nullptr) *bad_letter = l;
      return false;
    }
    switch (*c) {
      case Constellation::Gps: flags.use_gps = true; break;
      case Constellation::Glonass: flags.use_glonass = true; break;
      case Constellation::Galileo: flags.use_galileo = true; break;
      case Constellation::BeiDou: flags.use_beidou = true; break;
      case Constellation::Qzss: flags.use_qzss = true; break;
    }
  }
  *this = flags;
  return true;
}

const char* code_priority(Constellation system, char band) {
  switch (system) {
    case Constellation::Gps:
      switch (band) {
        case '1': return "CPWYMSLXN";
        case '2': return "WPYCLSXMDN";
        case '5': return "QXI";
        default: return "";
      }
    case Constellation::Glonass: return band == '1' || band == '2' ? "CP" : "QXI";
    case Constellation::Galileo:
      switch (band) {
        case '1': return "CXBAZ";
        case '5':
        case '7':
        case '8': return "QXI";
        case '6': return "CXBAZ";
        default: return "";
      }
    case Constellation::BeiDou: return "IQXDPZ";
    case Constellation::Qzss:
      switch (band) {
        case '1': return "CSLXBEZ";  // L1Z (L1-SAIF) last: a different signal
        case '2': return "LXS";
        case '5': return "QXIDPZ";
        case '6': return "LXSEZ";
        default: return "";
      }
  }
  return "";
}

}  // namespace canyon::core
