// RINEX observation reader: versions 2.10/2.11 and 3.00-3.05, mixed constellations, plain or gzip.
//
// The header is parsed once into RinexObsHeader and a per-system column mapping (column -> signal index and
// observable kind), so that reading an epoch is a walk over fixed 16-column fields without any lookup by name.
// Recoverable defects (short epochs, unsupported systems, odd header records) become warnings; a corrupt epoch in
// the body is skipped with a warning and reading resumes at the next epoch line; anything that makes the following
// data uninterpretable (a bad header, a body that is not observation data) is an Error naming the file and line.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>
#include <utility>

#include "canyon/io/rinex_obs.hpp"

namespace canyon::io {

namespace {

using core::Constellation;

enum class ObsKind : std::uint8_t { None, Pseudorange, Phase, Doppler, Snr };

ObsKind kind_from_letter(char letter) {
  switch (letter) {
    case 'C': return ObsKind::Pseudorange;
    case 'L': return ObsKind::Phase;
    case 'D': return ObsKind::Doppler;
    case 'S': return ObsKind::Snr;
    default: return ObsKind::None;
  }
}

constexpr std::size_t kFieldWidth = 16;  // F14.3 + LLI + SSI
constexpr std::size_t kValueWidth = 14;
constexpr std::size_t kV2FieldsPerLine = 5;
constexpr std::size_t kV2SatsPerLine = 12;
constexpr std::size_t kV3TypesPerLine = 13;
constexpr std::size_t kV2TypesPerLine = 9;
constexpr int kMaxSatellitesPerEpoch = 999;

struct TypeMap {
  const char* v2;
  const char* v3;
};

// RINEX 2 -> RINEX 3 observation codes (documented in rinex_obs.hpp).
constexpr TypeMap kV2Gps[] = {{"C1", "C1C"}, {"P1", "C1W"}, {"L1", "L1C"}, {"D1", "D1C"}, {"S1", "S1C"},
                              {"C2", "C2C"}, {"P2", "C2W"}, {"L2", "L2W"}, {"D2", "D2W"}, {"S2", "S2W"},
                              {"C5", "C5X"}, {"L5", "L5X"}, {"D5", "D5X"}, {"S5", "S5X"}};
constexpr TypeMap kV2Glonass[] = {{"C1", "C1C"}, {"P1", "C1P"}, {"L1", "L1C"}, {"D1", "D1C"}, {"S1", "S1C"},
                                  {"C2", "C2C"}, {"P2", "C2P"}, {"L2", "L2P"}, {"D2", "D2P"}, {"S2", "S2P"}};
constexpr TypeMap kV2Galileo[] = {{"C1", "C1X"}, {"L1", "L1X"}, {"D1", "D1X"}, {"S1", "S1X"}, {"C5", "C5X"},
                                  {"L5", "L5X"}, {"D5", "D5X"}, {"S5", "S5X"}, {"C6", "C6X"}, {"L6", "L6X"},
                                  {"D6", "D6X"}, {"S6", "S6X"}, {"C7", "C7X"}, {"L7", "L7X"}, {"D7", "D7X"},
                                  {"S7", "S7X"}, {"C8", "C8X"}, {"L8", "L8X"}, {"D8", "D8X"}, {"S8", "S8X"}};

template <std::size_t N>
std::string_view lookup(const TypeMap (&table)[N], std::string_view v2) {
  for (const TypeMap& t : table) {
    if (v2 == t.v2) return t.v3;
  }
  return {};
}

/// RINEX 3 code of a RINEX 2 type for a system; empty if canyon has no mapping for it.
std::string_view v2_to_v3(Constellation system, std::string_view v2) {
  switch (system) {
    case Constellation::Gps: return lookup(kV2Gps, v2);
    case Constellation::Glonass: return lookup(kV2Glonass, v2);
    case Constellation::Galileo: return lookup(kV2Galileo, v2);
    default: return {};
  }
}

/// Systems a RINEX 2 file declares its types for, from the file system letter.
std::vector<Constellation> v2_systems(char file_system) {
  switch (file_system) {
    case 'R': return {Constellation::Glonass};
    case 'E': return {Constellation::Galileo};
    case 'M': return {Constellation::Gps, Constellation::Glonass, Constellation::Galileo};
    default: return {Constellation::Gps};
  }
}

/// Letters of systems RINEX knows but canyon does not process: their records are skipped.
bool is_other_system(char letter) {
  return letter == 'S' || letter == 'I';
}

int system_index(Constellation c) {
  return static_cast<int>(c);
}

/// RINEX 3.00-3.02 BeiDou band '1' is B1I, which RINEX 3.03+ (and canyon) call band '2'.
std::string remap_code(Constellation system, std::string code, int version_code) {
  if (system == Constellation::BeiDou && version_code < 303 && code.size() == 3 && code[1] == '1') code[1] = '2';
  return code;
}

std::string format_version(double version) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", version);
  return text;
}

/// Fields of an epoch line.
struct EpochLine {
  core::CalendarTime time;
  bool time_blank = false;
  int flag = 0;
  int count = 0;
  double clock_offset_s = core::kNoValue;
};

struct EpochLayout {
  std::size_t year, year_width, month, day, hour, minute, second, flag, count, clock, clock_width;
};
constexpr EpochLayout kV3Epoch = {2, 4, 7, 10, 13, 16, 18, 31, 32, 41, 15};
constexpr EpochLayout kV2Epoch = {1, 2, 4, 7, 10, 13, 15, 28, 29, 68, 12};

/// Parses an epoch line; an error message if it is garbled.
std::optional<std::string> parse_epoch_line(std::string_view line, bool v3, EpochLine& out) {
  const EpochLayout& l = v3 ? kV3Epoch : kV2Epoch;
  const std::string_view fields[] = {
      column(line, l.year, l.year_width), column(line, l.month, 2),  column(line, l.day, 2), column(line, l.hour, 2),
      column(line, l.minute, 2),          column(line, l.second, 11)};
  out.time_blank = std::all_of(std::begin(fields), std::end(fields), [](auto f) { return trim(f).empty(); });
  const auto flag = parse_int(column(line, l.flag, 1), 0);
  if (!flag || *flag < 0 || *flag > 6) {
    return "bad epoch flag '" + std::string(column(line, l.flag, 1)) + "'";
  }
  out.flag = *flag;
  const bool event = out.flag >= 2 && out.flag <= 5;
  if (!(out.time_blank && event)) {
    const auto year = parse_int(fields[0]);
    const auto month = parse_int(fields[1]);
    const auto day = parse_int(fields[2]);
    const auto hour = parse_int(fields[3]);
    const auto minute = parse_int(fields[4]);
    const auto second = parse_double(fields[5]);
    if (!year || !month || !day || !hour || !minute || !second) {
      return "bad epoch time '" + std::string(trim(column(line, 0, l.second + 11))) + "'";
    }
    int full_year = *year;
    if (!v3) full_year += full_year < 80 ? 2000 : 1900;
    out.time = core::CalendarTime{full_year, *month, *day, *hour, *minute, *second};
    if (!core::is_valid(out.time) || full_year < 1980) {
      return "bad epoch date '" + std::string(trim(column(line, 0, l.second + 11))) + "'";
    }
  }
  const auto count = parse_int(column(line, l.count, 3), event ? std::optional<int>(0) : std::nullopt);
  if (!count || *count < 0 || *count > kMaxSatellitesPerEpoch) {
    return "bad satellite count '" + std::string(column(line, l.count, 3)) + "' in epoch line";
  }
  out.count = *count;
  const auto clock = parse_double(column(line, l.clock, l.clock_width), core::kNoValue);
  if (!clock) {
    return "bad receiver clock offset '" + std::string(trim(column(line, l.clock, l.clock_width))) + "'";
  }
  out.clock_offset_s = *clock;
  return std::nullopt;
}

/// A header label starts with two letters or with "#" (every RINEX label does); data lines do not.
bool looks_like_label(std::string_view label) {
  if (label.empty()) return false;
  if (label.front() == '#') return true;
  return label.size() >= 2 && std::isupper(static_cast<unsigned char>(label[0])) &&
         std::isupper(static_cast<unsigned char>(label[1]));
}

bool is_blank(std::string_view line) {
  return trim(line).empty();
}

/// `text` with bytes other than printable ASCII as '?': quoted file content in messages stays one terminal line.
std::string printable(std::string text) {
  for (char& c : text) {
    if (c < ' ' || c > '~') c = '?';
  }
  return text;
}

}  // namespace

/// Per-system column layout of the observation records.
struct RinexObsReader::Mapping {
  struct Column {
    std::int8_t signal = -1;  // index into `signals`, -1 for a column canyon ignores
    ObsKind kind = ObsKind::None;
    double scale = 1.0;     // "SYS / SCALE FACTOR": the file holds value * scale
    bool filtered = false;  // left out by the reader's filter: not even parsed
  };
  struct System {
    bool declared = false;
    bool filtered = false;  // the whole system is left out by the reader's filter
    std::vector<Column> columns;
    std::vector<core::SignalCode> signals;
  };
  std::array<System, core::kNumConstellations> systems;
  std::size_t v2_columns = 0;  // RINEX 2: the one type list shared by all systems
  std::size_t max_signals = 0;
};

// ---------------------------------------------------------------------------------------------------------------
// Header

Result<RinexObsReader> RinexObsReader::open(const std::string& path, std::optional<ObsFilter> filter) {
  auto text = TextReader::open(path);
  if (!text.ok()) return text.error();
  RinexObsReader reader(std::move(text).value());
  reader.filter_ = filter;
  if (Status s = reader.read_header(); !s.ok()) return s.error();
  return reader;
}

Error RinexObsReader::end_of_input_error(const std::string& message) {
  if (!reader_.read_error()) return reader_.error(message);
  read_error_reported_ = true;
  return reader_.error(message + " (" + *reader_.read_error() + ")");
}

void RinexObsReader::warn(int line, const std::string& message) {
  warnings_.push_back(reader_.path() + ":" + std::to_string(line) + ": " + printable(message));
}

Status RinexObsReader::read_version_line() {
  const auto first = reader_.next_line();
  if (!first) {
    if (reader_.read_error()) return reader_.error(*reader_.read_error());
    return reader_.error("empty file: no RINEX VERSION / TYPE line");
  }
  const std::string_view line = *first;
  const std::string_view label = trim(column(line, 60, 20));
  if (label.starts_with("CRINEX")) {
    return reader_.error("Hatanaka-compressed RINEX (CRINEX) is not supported; decompress it with crx2rnx first");
  }
  if (label != "RINEX VERSION / TYPE") {
    return reader_.error("not a RINEX file: the first line must be the RINEX VERSION / TYPE record");
  }
  const auto version = parse_double(column(line, 0, 9));
  if (!version) {
    return reader_.error("bad RINEX version '" + std::string(trim(column(line, 0, 9))) + "'");
  }
  header_.version = *version;
  version_code_ = static_cast<int>(std::lround(*version * 100.0));
  const char type = column(line, 20, 1).empty() ? ' ' : line[20];
  if (type != 'O') {
    const std::string what = (type == 'N' || type == 'G' || type == 'H') ? " (a navigation file)" : "";
    return reader_.error(std::string("not an observation file: file type '") + type + "'" + what);
  }
  const bool supported =
      (version_code_ >= 210 && version_code_ <= 211) || (version_code_ >= 300 && version_code_ <= 305);
  if (!supported) {
    return reader_.error("unsupported RINEX version " + format_version(*version) +
                         ", supported: 2.10-2.11, 3.02-3.05 (and 3.00-3.01)");
  }
  const std::string_view system = trim(column(line, 40, 1));
  header_.file_system = system.empty() ? (version_code_ < 300 ? 'G' : 'M') : system.front();
  if (header_.file_system != 'M' && !core::constellation_from_letter(header_.file_system)) {
    if (!is_other_system(header_.file_system)) {
      return reader_.error(std::string("bad satellite system '") + header_.file_system + "' in RINEX VERSION / TYPE");
    }
  }
  return Ok{};
}

Status RinexObsReader::read_header() {
  header_.time_system.clear();  // set by TIME OF FIRST OBS, else from the file's system in finish_header()
  if (Status s = read_version_line(); !s.ok()) return s;
  for (;;) {
    const auto next = reader_.next_line();
    if (!next) return end_of_input_error("missing END OF HEADER: the file ends inside the header");
    const std::string_view line = *next;
    const std::string_view label = trim(column(line, 60, 20));
    if (label == "END OF HEADER") {
      header_end_line_ = reader_.line_number();
      break;
    }
    if (is_blank(line)) {
      warn(reader_.line_number(), "blank line in the header, ignored");
      continue;
    }
    if (!looks_like_label(label)) {
      return reader_.error("missing END OF HEADER: line has no header label (observation data?)");
    }
    if (Status s = parse_header_record(line, label, false); !s.ok()) return s;
  }
  return finish_header();
}

Status RinexObsReader::parse_header_record(std::string_view line, std::string_view label, bool in_epoch) {
  if (label == "SYS / # / OBS TYPES") return parse_obs_types_v3(line);
  if (label == "# / TYPES OF OBSERV") return parse_obs_types_v2(line);
  if (continued_types_system_ != 0) {
    return Error{"observation types: fewer types than announced", reader_.path(), obs_types_line_};
  }
  if (label == "RINEX VERSION / TYPE") {
    return reader_.error("RINEX VERSION / TYPE must be the first line only");
  }
  if (label == "MARKER NAME") {
    header_.receiver.marker_name = std::string(trim(column(line, 0, 60)));
  } else if (label == "REC # / TYPE / VERS") {
    header_.receiver.receiver_type = std::string(trim(column(line, 20, 20)));
  } else if (label == "ANT # / TYPE") {
    header_.receiver.antenna_type = std::string(trim(column(line, 20, 20)));
  } else if (label == "APPROX POSITION XYZ" || label == "ANTENNA: DELTA H/E/N") {
    const auto x = parse_double(column(line, 0, 14), 0.0);
    const auto y = parse_double(column(line, 14, 14), 0.0);
    const auto z = parse_double(column(line, 28, 14), 0.0);
    if (!x || !y || !z) {
      warn(reader_.line_number(), "bad " + std::string(label) + " record, ignored");
    } else if (label == "ANTENNA: DELTA H/E/N") {
      header_.receiver.antenna_delta_hen_m = Eigen::Vector3d(*x, *y, *z);
    } else if (*x == 0.0 && *y == 0.0 && *z == 0.0) {
      header_.receiver.approx_position_E_m.reset();
    } else {
      header_.receiver.approx_position_E_m = Eigen::Vector3d(*x, *y, *z);
    }
  } else if (label == "INTERVAL") {
    const auto interval = parse_double(column(line, 0, 10));
    if (interval && *interval >= 0.0) {
      header_.interval_s = *interval;
    } else {
      warn(reader_.line_number(), "bad INTERVAL record, ignored");
    }
  } else if (label == "LEAP SECONDS") {
    const auto leap = parse_int(column(line, 0, 6));
    if (leap) {
      header_.leap_seconds = *leap;
    } else {
      warn(reader_.line_number(), "bad LEAP SECONDS record, ignored");
    }
  } else if (label == "TIME OF FIRST OBS") {
    if (!in_epoch) return parse_time_of_first_obs(line);
  } else if (label == "GLONASS SLOT / FRQ #") {
    return parse_glonass_slots(line);
  } else if (label == "SYS / PHASE SHIFT" || label == "SYS / PHASE SHIFTS") {
    parse_phase_shift(line);
  } else if (label == "SYS / SCALE FACTOR") {
    return parse_scale_factor(line);
  }
  return Ok{};
}

Status RinexObsReader::parse_obs_types_v3(std::string_view line) {
  if (version_code_ < 300) return reader_.error("SYS / # / OBS TYPES in a RINEX 2 file");
  obs_types_line_ = reader_.line_number();
  const std::string_view system_field = column(line, 0, 1);
  std::vector<std::string>* types = nullptr;
  if (system_field.empty() || system_field[0] == ' ') {
    if (continued_types_system_ == 0) {
      return reader_.error("SYS / # / OBS TYPES continuation line without a system");
    }
  } else {
    const auto count = parse_int(column(line, 3, 3));
    if (!count || *count < 0) return reader_.error("bad number of observation types in SYS / # / OBS TYPES");
    continued_types_system_ = system_field[0];
    expected_types_ = static_cast<std::size_t>(*count);
    const auto system = core::constellation_from_letter(continued_types_system_);
    if (!system && !is_other_system(continued_types_system_)) {
      return reader_.error("unknown satellite system '" + std::string(system_field) + "' in SYS / # / OBS TYPES");
    }
    if (system) header_.obs_types[*system].clear();
  }
  const auto system = core::constellation_from_letter(continued_types_system_);
  if (system) types = &header_.obs_types[*system];
  std::size_t& done = expected_types_;  // counts down the types still to come
  for (std::size_t k = 0; k < kV3TypesPerLine && done > 0; ++k) {
    const std::string_view code = trim(column(line, 7 + 4 * k, 3));
    if (code.empty()) break;
    if (types != nullptr) types->push_back(remap_code(*system, std::string(code), version_code_));
    --done;
  }
  if (done == 0) continued_types_system_ = 0;
  return Ok{};
}

Status RinexObsReader::parse_obs_types_v2(std::string_view line) {
  if (version_code_ >= 300) return reader_.error("# / TYPES OF OBSERV in a RINEX 3 file");
  obs_types_line_ = reader_.line_number();
  const std::string_view count_field = trim(column(line, 0, 6));
  if (!count_field.empty()) {
    const auto count = parse_int(count_field);
    if (!count || *count < 0) return reader_.error("bad number of observation types in # / TYPES OF OBSERV");
    v2_types_.clear();
    expected_types_ = static_cast<std::size_t>(*count);
    continued_types_system_ = 'v';
  } else if (continued_types_system_ != 'v') {
    return reader_.error("# / TYPES OF OBSERV continuation line without a count");
  }
  for (std::size_t k = 0; k < kV2TypesPerLine && expected_types_ > 0; ++k) {
    const std::string_view type = trim(column(line, 10 + 6 * k, 2));
    if (type.empty()) break;
    v2_types_.emplace_back(type);
    --expected_types_;
  }
  if (expected_types_ == 0) continued_types_system_ = 0;
  return Ok{};
}

Status RinexObsReader::parse_time_of_first_obs(std::string_view line) {
  const auto year = parse_int(column(line, 0, 6));
  const auto month = parse_int(column(line, 6, 6));
  const auto day = parse_int(column(line, 12, 6));
  const auto hour = parse_int(column(line, 18, 6));
  const auto minute = parse_int(column(line, 24, 6));
  const auto second = parse_double(column(line, 30, 13));
  if (!year || !month || !day || !hour || !minute || !second) return reader_.error("bad TIME OF FIRST OBS");
  const core::CalendarTime c{*year, *month, *day, *hour, *minute, *second};
  if (!core::is_valid(c)) return reader_.error("bad date in TIME OF FIRST OBS");
  first_obs_calendar_ = c;
  const std::string_view system = trim(column(line, 48, 3));
  if (!system.empty()) header_.time_system = std::string(system);
  return Ok{};
}

Status RinexObsReader::parse_glonass_slots(std::string_view line) {
  for (std::size_t k = 0; k < 8; ++k) {
    const std::string_view sat_field = trim(column(line, 4 + 7 * k, 3));
    if (sat_field.empty()) continue;
    const auto sat = core::parse_satellite(sat_field);
    const auto channel = parse_int(column(line, 8 + 7 * k, 2));
    if (!sat || sat->system != Constellation::Glonass || !channel || *channel < -7 || *channel > 13) {
      return reader_.error("bad GLONASS SLOT / FRQ # entry '" + std::string(trim(column(line, 4 + 7 * k, 6))) + "'");
    }
    auto& slots = header_.receiver.glonass_slot_channels;
    std::erase_if(slots, [&](const auto& p) { return p.first == sat->prn; });
    slots.emplace_back(sat->prn, *channel);
  }
  return Ok{};
}

void RinexObsReader::parse_phase_shift(std::string_view line) {
  const std::string_view system_field = column(line, 0, 1);
  if (system_field.empty() || system_field[0] == ' ') return;  // continuation: satellite list, not kept
  const auto system = core::constellation_from_letter(system_field[0]);
  if (!system) return;
  const std::string_view code = trim(column(line, 2, 3));
  if (code.empty()) return;  // "system without phase shift information"
  const std::string mapped = remap_code(*system, std::string(code), version_code_);
  const auto signal = core::parse_signal(std::string_view(mapped).substr(1));
  const auto shift = parse_double(column(line, 6, 8), 0.0);
  if (mapped.size() != 3 || mapped[0] != 'L' || !signal || !shift) {
    warn(reader_.line_number(), "bad SYS / PHASE SHIFT record, ignored");
    return;
  }
  header_.receiver.phase_shifts.push_back({*system, *signal, *shift});
}

Status RinexObsReader::parse_scale_factor(std::string_view line) {
  const std::string_view system_field = column(line, 0, 1);
  if (!system_field.empty() && system_field[0] != ' ') {
    const auto factor = parse_int(column(line, 2, 4));
    if (!factor || (*factor != 1 && *factor != 10 && *factor != 100 && *factor != 1000)) {
      return reader_.error("bad SYS / SCALE FACTOR '" + std::string(trim(column(line, 2, 4))) +
                           "' (1, 10, 100 or 1000)");
    }
    continued_scale_ = {system_field[0], "", static_cast<double>(*factor)};
    const auto count = parse_int(column(line, 8, 2), 0);
    if (!count || *count == 0) {  // no list: every type of the system
      scale_factors_.push_back(continued_scale_);
      return Ok{};
    }
  } else if (continued_scale_.system == 0) {
    return reader_.error("SYS / SCALE FACTOR continuation line without a system");
  }
  const auto system = core::constellation_from_letter(continued_scale_.system);
  for (std::size_t k = 0; k < 12; ++k) {
    const std::string_view code = trim(column(line, 11 + 4 * k, 3));
    if (code.empty()) continue;
    ScaleFactor f = continued_scale_;
    f.code = system ? remap_code(*system, std::string(code), version_code_) : std::string(code);
    scale_factors_.push_back(f);
  }
  return Ok{};
}

core::GpsTime RinexObsReader::to_gps(const core::CalendarTime& c) const {
  const std::string& ts = header_.time_system;
  if (ts == "GLO") return core::glonass_to_gps(c, leaps_);
  if (ts == "BDT") return core::calendar_to_gps(c) - core::kBdtMinusGpstS;
  return core::calendar_to_gps(c);  // GPS, GAL, QZS (and IRN): GPST seconds
}

Status RinexObsReader::finish_header() {
  if (continued_types_system_ != 0) {
    return Error{"observation types: fewer types than announced", reader_.path(), obs_types_line_};
  }
  const bool v3 = version_code_ >= 300;
  if (v3 ? header_.obs_types.empty() : v2_types_.empty()) {
    return reader_.error(std::string("no observation types: missing ") +
                         (v3 ? "SYS / # / OBS TYPES" : "# / TYPES OF OBSERV") + " before the data");
  }
  if (!v3) {
    for (const Constellation system : v2_systems(header_.file_system)) {
      auto& codes = header_.obs_types[system];
      for (const std::string& type : v2_types_) {
        const std::string_view code = v2_to_v3(system, type);
        if (!code.empty()) codes.emplace_back(code);
      }
    }
  }
  // Time system of the epochs: TIME OF FIRST OBS says it, else the file's single system does.
  if (header_.time_system.empty()) {
    switch (header_.file_system) {
      case 'R': header_.time_system = "GLO"; break;
      case 'E': header_.time_system = "GAL"; break;
      case 'C': header_.time_system = "BDT"; break;
      case 'J': header_.time_system = "QZS"; break;
      default: header_.time_system = "GPS"; break;
    }
  }
  static constexpr std::array<std::string_view, 6> kKnown = {"GPS", "GLO", "GAL", "BDT", "QZS", "IRN"};
  if (std::find(kKnown.begin(), kKnown.end(), header_.time_system) == kKnown.end()) {
    warn(reader_.line_number(), "unknown time system '" + header_.time_system + "', GPS time assumed");
    header_.time_system = "GPS";
  }
  leaps_ = header_.leap_seconds
               ? core::LeapSecondTable({{core::CalendarTime{1980, 1, 6, 0, 0, 0.0}, *header_.leap_seconds}})
               : core::builtin_leap_seconds();
  if (first_obs_calendar_) header_.first_obs = to_gps(*first_obs_calendar_);
  build_mapping();
  return Ok{};
}

void RinexObsReader::build_mapping() {
  auto mapping = std::make_shared<Mapping>();
  const bool v3 = version_code_ >= 300;
  mapping->v2_columns = v2_types_.size();
  for (const auto& [system, codes] : header_.obs_types) {
    Mapping::System& m = mapping->systems[static_cast<std::size_t>(system_index(system))];
    m.declared = true;
    m.filtered = filter_ && !filter_->systems.uses(system);
    const std::size_t columns = v3 ? codes.size() : v2_types_.size();
    m.columns.assign(columns, Mapping::Column{});
    for (std::size_t k = 0; k < columns; ++k) {
      const std::string code = v3 ? codes[k] : std::string(v2_to_v3(system, v2_types_[k]));
      if (code.size() != 3) continue;
      const ObsKind kind = kind_from_letter(code[0]);
      const auto signal = core::parse_signal(std::string_view(code).substr(1));
      if (kind == ObsKind::None || !signal) continue;  // e.g. Septentrio's "X1" channel numbers
      if (filter_) {
        const auto rank = core::frequency_rank(system, signal->band);
        if (!rank || *rank > filter_->max_frequency_rank) {
          m.columns[k].filtered = true;
          continue;
        }
      }
      auto it = std::find(m.signals.begin(), m.signals.end(), *signal);
      if (it == m.signals.end()) it = m.signals.insert(m.signals.end(), *signal);
      double scale = 1.0;
      for (const ScaleFactor& f : scale_factors_) {
        if (f.system == core::system_letter(system) && (f.code.empty() || f.code == code)) scale = f.factor;
      }
      m.columns[k] = {static_cast<std::int8_t>(it - m.signals.begin()), kind, scale};
    }
    mapping->max_signals = std::max(mapping->max_signals, m.signals.size());
  }
  scratch_.assign(mapping->max_signals, core::SignalObs{});
  mapping_ = std::move(mapping);
}

// ---------------------------------------------------------------------------------------------------------------
// Epochs

Status RinexObsReader::skip_event_records(int count) {
  const bool v3 = version_code_ >= 300;
  bool types_changed = false;
  for (int i = 0; i < count; ++i) {
    const auto next = reader_.next_line();
    if (!next) {
      warn(reader_.line_number(), end_of_input_error("file ends inside the header records of an event epoch").message);
      return Ok{};
    }
    const std::string_view line = *next;
    if (v3 ? line.starts_with('>') : is_epoch_line(line)) {
      warn(reader_.line_number(),
           "event epoch announces " + std::to_string(count) + " header records, " + std::to_string(i) + " present");
      reader_.unread_line();
      break;
    }
    const std::string_view label = trim(column(line, 60, 20));
    if (!looks_like_label(label)) {
      warn(reader_.line_number(), "event epoch record without a header label, ignored");
      continue;
    }
    types_changed = types_changed || label == "SYS / # / OBS TYPES" || label == "# / TYPES OF OBSERV";
    if (Status s = parse_header_record(line, label, true); !s.ok()) return s;
  }
  if (types_changed) {
    if (continued_types_system_ != 0) {
      return Error{"observation types: fewer types than announced", reader_.path(), obs_types_line_};
    }
    if (version_code_ < 300) {
      for (const Constellation system : v2_systems(header_.file_system)) {
        auto& codes = header_.obs_types[system];
        codes.clear();
        for (const std::string& type : v2_types_) {
          const std::string_view code = v2_to_v3(system, type);
          if (!code.empty()) codes.emplace_back(code);
        }
      }
    }
    build_mapping();
  }
  return Ok{};
}

Result<std::optional<core::SatelliteId>> RinexObsReader::resolve_satellite(std::string_view token) {
  char text[3] = {' ', ' ', ' '};
  std::copy_n(token.begin(), std::min<std::size_t>(token.size(), 3), text);
  if (text[0] == ' ' && version_code_ < 300) text[0] = 'G';  // RINEX 2: blank means GPS
  const std::string_view id(text, 3);
  if (const auto sat = core::parse_satellite(id)) {
    const Mapping::System& system = mapping_->systems[static_cast<std::size_t>(system_index(sat->system))];
    if (system.declared && system.filtered) return std::optional<core::SatelliteId>{};  // not wanted: no warning
    if (system.declared) return std::optional<core::SatelliteId>(*sat);
    if (warned_systems_.find(text[0]) == std::string::npos) {
      warned_systems_.push_back(text[0]);
      warn(reader_.line_number(), "satellite " + sat->to_string() + ": no observation types declared for " +
                                      std::string(core::constellation_name(sat->system)) +
                                      ", records of the system skipped");
    }
    return std::optional<core::SatelliteId>{};
  }
  const bool numeric = parse_int(id.substr(1)).has_value();
  if (numeric && is_other_system(text[0])) {
    if (warned_systems_.find(text[0]) == std::string::npos) {
      warned_systems_.push_back(text[0]);
      warn(reader_.line_number(), std::string("records of system '") + text[0] + "' are not supported, skipped");
    }
    return std::optional<core::SatelliteId>{};
  }
  if (numeric && core::constellation_from_letter(text[0])) {
    const std::string name(id);
    if (std::find(warned_satellites_.begin(), warned_satellites_.end(), name) == warned_satellites_.end()) {
      warned_satellites_.push_back(name);
      warn(reader_.line_number(), "satellite number '" + name + "' out of canyon's range, its records skipped");
    }
    return std::optional<core::SatelliteId>{};
  }
  return reader_.error("bad satellite '" + std::string(trim(token)) + "'");
}

Status RinexObsReader::parse_fields(std::string_view line, std::size_t first_col, std::size_t first_field,
                                    std::size_t count, Constellation system) {
  const Mapping::System& m = mapping_->systems[static_cast<std::size_t>(system_index(system))];
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t pos = first_col + kFieldWidth * i;
    if (pos >= line.size()) break;
    if (first_field + i < m.columns.size() && m.columns[first_field + i].filtered) continue;
    const std::string_view field = column(line, pos, kValueWidth);
    if (field.size() < kValueWidth && !is_blank(field)) {  // values are right-aligned: the line was cut
      return reader_.error("observation value '" + std::string(trim(field)) + "' cut short in column " +
                           std::to_string(pos + 1) + " (the line ends inside the field)");
    }
    const auto value = parse_double(field, 0.0);
    if (!value) {
      return reader_.error("bad observation value '" + std::string(trim(field)) + "' in column " +
                           std::to_string(pos + 1));
    }
    const std::size_t k = first_field + i;
    if (*value == 0.0 || k >= m.columns.size() || m.columns[k].signal < 0) continue;
    const Mapping::Column& c = m.columns[k];
    const double v = c.scale == 1.0 ? *value : *value / c.scale;
    core::SignalObs& s = scratch_[static_cast<std::size_t>(c.signal)];
    switch (c.kind) {
      case ObsKind::Pseudorange: s.pseudorange_m = v; break;
      case ObsKind::Phase: {
        s.carrier_phase_cyc = v;
        const char lli = pos + kValueWidth < line.size() ? line[pos + kValueWidth] : ' ';
        s.lli = (lli >= '0' && lli <= '9') ? static_cast<std::uint8_t>(lli - '0') : 0;
        break;
      }
      case ObsKind::Doppler: s.doppler_hz = v; break;
      case ObsKind::Snr: s.snr_dbhz = v; break;
      case ObsKind::None: break;
    }
  }
  return Ok{};
}

void RinexObsReader::emit_satellite(core::SatelliteId sat, core::ObsEpoch& epoch) {
  const Mapping::System& m = mapping_->systems[static_cast<std::size_t>(system_index(sat.system))];
  core::SatelliteObs& out = epoch.sats.emplace_back();
  out.sat = sat;
  std::size_t present = 0;
  for (std::size_t i = 0; i < m.signals.size(); ++i) {
    const core::SignalObs& s = scratch_[i];
    present += (core::has_value(s.pseudorange_m) || core::has_value(s.carrier_phase_cyc) ||
                core::has_value(s.doppler_hz) || core::has_value(s.snr_dbhz))
                   ? 1
                   : 0;
  }
  out.signals.reserve(present);
  for (std::size_t i = 0; i < m.signals.size(); ++i) {
    core::SignalObs& s = scratch_[i];
    if (core::has_value(s.pseudorange_m) || core::has_value(s.carrier_phase_cyc) || core::has_value(s.doppler_hz) ||
        core::has_value(s.snr_dbhz)) {
      s.code = m.signals[i];
      out.signals.push_back(s);
    }
    s = core::SignalObs{};
  }
}

Status RinexObsReader::read_satellites_v3(core::ObsEpoch& epoch, int count, int epoch_line) {
  epoch.sats.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const auto next = reader_.next_line();
    if (!next) {
      return end_of_input_error("file ends inside an epoch: " + std::to_string(count) + " satellites announced, " +
                                std::to_string(i) + " present");
    }
    const std::string_view line = *next;
    if (line.starts_with('>')) {
      warn(epoch_line, "epoch announces " + std::to_string(count) + " satellites, " + std::to_string(i) + " present");
      reader_.unread_line();
      return Ok{};
    }
    auto sat = resolve_satellite(column(line, 0, 3));
    if (!sat.ok()) return sat.error();
    if (!*sat) continue;
    const auto& m = mapping_->systems[static_cast<std::size_t>(system_index((*sat)->system))];
    if (Status s = parse_fields(line, 3, 0, m.columns.size(), (*sat)->system); !s.ok()) return s;
    emit_satellite(**sat, epoch);
  }
  return Ok{};
}

Status RinexObsReader::read_sat_list_v2(std::string_view epoch_line, int count) {
  sat_tokens_.clear();
  std::string line(epoch_line);
  for (int k = 0; k < count; ++k) {
    const std::size_t slot = static_cast<std::size_t>(k) % kV2SatsPerLine;
    if (k > 0 && slot == 0) {
      const auto next = reader_.next_line();
      if (!next) return end_of_input_error("file ends inside the satellite list of an epoch");
      if (is_epoch_line(*next)) {
        return reader_.error("epoch announces " + std::to_string(count) + " satellites, " + std::to_string(k) +
                             " listed");
      }
      line.assign(*next);
    }
    const std::string_view token = column(line, 32 + 3 * slot, 3);
    if (trim(token).empty()) {
      return reader_.error("epoch announces " + std::to_string(count) + " satellites, " + std::to_string(k) +
                           " listed");
    }
    sat_tokens_.emplace_back(token);
  }
  return Ok{};
}

Status RinexObsReader::read_satellites_v2(core::ObsEpoch& epoch) {
  const std::size_t types = mapping_->v2_columns;
  const std::size_t lines_per_sat = std::max<std::size_t>(1, (types + kV2FieldsPerLine - 1) / kV2FieldsPerLine);
  epoch.sats.reserve(sat_tokens_.size());
  for (const std::string& token : sat_tokens_) {
    auto sat = resolve_satellite(token);
    if (!sat.ok()) return sat.error();
    for (std::size_t l = 0; l < lines_per_sat; ++l) {
      const auto next = reader_.next_line();
      if (!next) {
        return end_of_input_error("file ends inside an epoch: records of " + std::to_string(sat_tokens_.size()) +
                                  " satellites announced");
      }
      if (!*sat) continue;
      const std::size_t first = l * kV2FieldsPerLine;
      const std::size_t n = std::min(kV2FieldsPerLine, types - std::min(types, first));
      if (Status s = parse_fields(*next, 0, first, n, (*sat)->system); !s.ok()) {
        if (!is_epoch_line(*next)) return s;
        return reader_.error("epoch line where a satellite record was expected: records of " +
                             std::to_string(sat_tokens_.size()) + " satellites announced, fewer present");
      }
    }
    if (*sat) emit_satellite(**sat, epoch);
  }
  return Ok{};
}

bool RinexObsReader::is_epoch_line(std::string_view line) const {
  const bool v3 = version_code_ >= 300;
  if (v3 && !line.starts_with('>')) return false;
  EpochLine fields;
  if (parse_epoch_line(line, v3, fields)) return false;
  if (v3 || (fields.flag >= 2 && fields.flag <= 5)) return true;
  const int listed = std::min(fields.count, static_cast<int>(kV2SatsPerLine));
  for (int k = 0; k < listed; ++k) {
    const std::string_view token = column(line, 32 + 3 * static_cast<std::size_t>(k), 3);
    const char system = token.empty() ? ' ' : token[0];
    const bool letter = system == ' ' || core::constellation_from_letter(system) || is_other_system(system);
    const auto number = parse_int(column(token, 1, 2));
    if (!letter || !number || *number <= 0) return false;
  }
  return true;
}

Status RinexObsReader::read_records(core::ObsEpoch& epoch, std::string_view line, int count, int epoch_line) {
  if (version_code_ >= 300) return read_satellites_v3(epoch, count, epoch_line);
  if (Status s = read_sat_list_v2(line, count); !s.ok()) return s;
  return read_satellites_v2(epoch);
}

Result<int> RinexObsReader::resynchronise() {
  int garbled_epoch_lines = 0;
  for (;;) {
    const auto next = reader_.next_line();
    if (!next) return garbled_epoch_lines;
    if (is_epoch_line(*next)) {
      reader_.unread_line();
      return garbled_epoch_lines;
    }
    if (version_code_ >= 300 && next->starts_with('>')) ++garbled_epoch_lines;
    if (!epoch_line_seen_ && reader_.line_number() - header_end_line_ >= kMaxLinesBeforeFirstEpoch) {
      return reader_.error("no epoch line in the " + std::to_string(kMaxLinesBeforeFirstEpoch) +
                           " lines after the header: not RINEX " + format_version(header_.version) +
                           " observation data");
    }
  }
}

Status RinexObsReader::skip_corrupt_epoch(const Error& problem, int first_line) {
  // The line where the problem showed may be the next epoch's (an epoch announcing more records than it holds):
  // it is examined again, unless it is the corrupt epoch's own first line.
  if (!reader_.ended() && reader_.line_number() > first_line) reader_.unread_line();
  const auto garbled = resynchronise();
  if (!garbled.ok()) return garbled.error();
  const int epochs = 1 + *garbled;
  const int last_line = std::max(first_line, reader_.line_number());
  std::string message = problem.message + ", ";
  message += epochs == 1 ? "epoch" : std::to_string(epochs) + " epochs";
  message += " skipped (";
  message += last_line == first_line ? "line " + std::to_string(first_line)
                                     : "lines " + std::to_string(first_line) + "-" + std::to_string(last_line);
  message += ")";
  warn(problem.line, message);
  if (corrupt_epochs_ == 0) first_corruption_ = Error{printable(message), reader_.path(), problem.line};
  corrupt_epochs_ += epochs;
  return Ok{};
}

bool RinexObsReader::in_time_order(const core::ObsEpoch& epoch, const core::CalendarTime& time, int epoch_line) {
  if (epoch.flag == core::EpochFlag::CycleSlipRecords) return true;  // repeats the time of the epoch it amends
  if (last_time_ && epoch.time - *last_time_ <= 0.0) {
    const bool same = epoch.time - *last_time_ == 0.0;
    std::string message = "epoch " + core::format_calendar(time, 7);
    message += same ? " repeats the time of" : " is earlier than";
    message += " the epoch of line " + std::to_string(last_time_line_) + ", epoch skipped";
    warn(epoch_line, message);
    return false;
  }
  last_time_ = epoch.time;
  last_time_line_ = epoch_line;
  return true;
}

Result<std::optional<core::ObsEpoch>> RinexObsReader::end_of_body() {
  if (reader_.read_error() && !read_error_reported_) {
    read_error_reported_ = true;
    warn(reader_.line_number(), *reader_.read_error() + ": reading stops here, the epochs before are kept");
  }
  if (corrupt_epochs_ > valid_epochs_) {
    Error error = first_corruption_;
    error.message = "not usable observation data, " + std::to_string(corrupt_epochs_) + " of the " +
                    std::to_string(corrupt_epochs_ + valid_epochs_) +
                    " epochs are corrupt; the first: " + error.message;
    return error;
  }
  return std::optional<core::ObsEpoch>{};
}

Result<std::optional<core::ObsEpoch>> RinexObsReader::next() {
  const bool v3 = version_code_ >= 300;
  for (;;) {
    const auto next = reader_.next_line();
    if (!next) return end_of_body();
    const std::string_view line = *next;
    if (is_blank(line)) continue;
    const int epoch_line = reader_.line_number();
    EpochLine fields;
    std::optional<std::string> problem;
    if (v3 && !line.starts_with('>')) {
      problem = "expected an epoch line starting with '>', got '" + std::string(column(line, 0, 20)) + "'";
    } else {
      problem = parse_epoch_line(line, v3, fields);
    }
    if (problem) {
      if (Status s = skip_corrupt_epoch(reader_.error(*problem), epoch_line); !s.ok()) return s.error();
      continue;
    }
    epoch_line_seen_ = true;
    if (fields.flag >= 2 && fields.flag <= 5) {
      if (Status s = skip_event_records(fields.count); !s.ok()) return s.error();
      continue;
    }
    core::ObsEpoch epoch;
    epoch.time = to_gps(fields.time);
    epoch.flag = static_cast<core::EpochFlag>(fields.flag);
    epoch.receiver_clock_offset_s = fields.clock_offset_s;
    Status read = read_records(epoch, line, fields.count, epoch_line);
    if (reader_.line_cut()) read = end_of_input_error("file ends inside an epoch, its last line cut short");
    if (!read.ok()) {
      if (Status s = skip_corrupt_epoch(read.error(), epoch_line); !s.ok()) return s.error();
      continue;
    }
    if (!in_time_order(epoch, fields.time, epoch_line)) continue;
    ++valid_epochs_;
    return std::optional<core::ObsEpoch>(std::move(epoch));
  }
}

Result<RinexObsFile> read_rinex_obs(const std::string& path, std::optional<ObsFilter> filter) {
  auto reader = RinexObsReader::open(path, filter);
  if (!reader.ok()) return reader.error();
  RinexObsFile file;
  for (;;) {
    auto epoch = reader->next();
    if (!epoch.ok()) return epoch.error();
    if (!*epoch) break;
    file.epochs.push_back(std::move(**epoch));
  }
  file.header = reader->header();
  file.warnings = reader->warnings();
  return file;
}

void apply_obs_filter(const ObsFilter& filter, core::ObsEpoch& epoch) {
  const auto kept_signal = [&filter](core::Constellation system, const core::SignalObs& signal) {
    const auto rank = core::frequency_rank(system, signal.code.band);
    return rank && *rank <= filter.max_frequency_rank;
  };
  for (core::SatelliteObs& sat : epoch.sats) {
    if (!filter.systems.uses(sat.sat.system)) {
      sat.signals.clear();
      continue;
    }
    std::erase_if(sat.signals, [&](const core::SignalObs& s) { return !kept_signal(sat.sat.system, s); });
  }
  std::erase_if(epoch.sats, [](const core::SatelliteObs& sat) { return sat.signals.empty(); });
}

}  // namespace canyon::io
