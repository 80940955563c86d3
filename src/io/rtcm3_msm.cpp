// RTCM 3 Multiple Signal Messages (RTCM 10403.3 section 3.5.12): header, satellite and signal data of MSM4-MSM7
// (fields in rtcm3_fields.hpp; here the rough and fine ranges, masks and invalid values), signal ids, lock time
// indicators and epoch times; and the RTCM 3 frame (section 4).

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>

#include "canyon/io/bits.hpp"
#include "canyon/io/rtcm3.hpp"
#include "canyon/io/rtcm3_fields.hpp"

namespace canyon::io::rtcm3 {
namespace {

using core::Constellation;

constexpr std::size_t kMsmHeaderBits = fields::msm_header_bits();  // without the cell mask
constexpr int kMaxCells = 64;

/// RTCM 10403.3 tables 3.5-91 (GPS), 3.5-96 (GLONASS), 3.5-99 (Galileo), 3.5-105 (QZSS), 3.5-108 (BeiDou): RINEX
/// code of signal ids 1-32 ("" = reserved).
using SignalTable = std::array<const char*, 32>;
constexpr SignalTable kGpsSignals = {"",   "1C", "1P", "1W", "",   "",   "", "2C", "2P", "2W", "",
                                     "",   "",   "",   "2S", "2L", "2X", "", "",   "",   "",   "5I",
                                     "5Q", "5X", "",   "",   "",   "",   "", "1S", "1L", "1X"};
constexpr SignalTable kGlonassSignals = {"", "1C", "1P", "", "", "", "", "2C", "2P", "", "", "", "", "", "", "",
                                         "", "",   "",   "", "", "", "", "",   "",   "", "", "", "", "", "", ""};
constexpr SignalTable kGalileoSignals = {"",   "1C", "1A", "1B", "1X", "1Z", "",   "6C", "6A", "6B", "6X",
                                         "6Z", "",   "7I", "7Q", "7X", "",   "8I", "8Q", "8X", "",   "5I",
                                         "5Q", "5X", "",   "",   "",   "",   "",   "",   "",   ""};
constexpr SignalTable kQzssSignals = {"",   "1C", "", "",   "",   "",   "", "",   "6S", "6L", "6X",
                                      "",   "",   "", "2S", "2L", "2X", "", "",   "",   "",   "5I",
                                      "5Q", "5X", "", "",   "",   "",   "", "1S", "1L", "1X"};
constexpr SignalTable kBeidouSignals = {"",   "2I", "2Q", "2X", "",   "", "", "6I", "6Q", "6X", "",
                                        "",   "",   "7I", "7Q", "7X", "", "", "",   "",   "",   "5D",
                                        "5P", "5X", "7D", "",   "",   "", "", "1D", "1P", "1X"};

constexpr const SignalTable& signal_table(Constellation system) {
  switch (system) {
    case Constellation::Gps: return kGpsSignals;
    case Constellation::Glonass: return kGlonassSignals;
    case Constellation::Galileo: return kGalileoSignals;
    case Constellation::Qzss: return kQzssSignals;
    case Constellation::BeiDou: return kBeidouSignals;
  }
  return kGpsSignals;
}

int message_base(Constellation system) {
  switch (system) {
    case Constellation::Gps: return 1070;
    case Constellation::Glonass: return 1080;
    case Constellation::Galileo: return 1090;
    case Constellation::Qzss: return 1110;
    case Constellation::BeiDou: return 1120;
  }
  return 1070;
}

constexpr int kInvalidRoughInt = 255;              // DF397
constexpr std::int64_t kInvalidRate = -8192;       // DF399
constexpr std::int64_t kInvalidFineRate = -16384;  // DF404

std::string message_text(int number) {
  return "RTCM 3 message " + std::to_string(number);
}

/// Rounds x / lsb to an integer that fits a signed field of `bits` bits without its most negative value (the
/// "invalid" marker); nullopt otherwise. Rounds half away from zero, inline (std::round is a libm call).
std::optional<std::int64_t> fit_signed(double x, double lsb, unsigned bits) {
  const double scaled = x / lsb;
  const auto limit = static_cast<double>(std::int64_t{1} << (bits - 1));
  if (!(scaled > -limit && scaled < limit)) return std::nullopt;
  const auto q = static_cast<std::int64_t>(scaled + (scaled >= 0.0 ? 0.5 : -0.5));
  if (q <= -static_cast<std::int64_t>(limit) || q >= static_cast<std::int64_t>(limit)) return std::nullopt;
  return q;
}

/// RINEX code -> MSM signal id per system, built at compile time from the tables above.
constexpr std::size_t kCodeSlots = std::size_t{10} * 26;  // band digit x attribute letter

constexpr std::size_t code_slot(char band, char attribute) {
  return static_cast<std::size_t>(band - '0') * 26 + static_cast<std::size_t>(attribute - 'A');
}

struct SignalIdLookup {
  std::array<std::array<std::uint8_t, kCodeSlots>, core::kNumConstellations> ids{};
  constexpr SignalIdLookup() {
    for (int c = 0; c < core::kNumConstellations; ++c) {
      const SignalTable& table = signal_table(static_cast<Constellation>(c));
      for (std::size_t i = 0; i < table.size(); ++i) {
        const char* code = table[i];
        if (code[0] == '\0') continue;
        ids[static_cast<std::size_t>(c)][code_slot(code[0], code[1])] = static_cast<std::uint8_t>(i + 1);
      }
    }
  }
};
constexpr SignalIdLookup kSignalIds{};

std::int64_t invalid_marker(unsigned bits) {
  return -(std::int64_t{1} << (bits - 1));
}

}  // namespace

int message_number(std::span<const std::uint8_t> payload) {
  if (payload.size() < 2) return 0;
  return (payload[0] << 4) | (payload[1] >> 4);
}

Status append_frame(std::span<const std::uint8_t> payload, std::vector<std::uint8_t>& out) {
  if (payload.size() > kMaxPayloadBytes) {
    return Error{"RTCM 3 payload of " + std::to_string(payload.size()) + " bytes exceeds 1023"};
  }
  const std::size_t start = out.size();
  out.push_back(0xD3);
  out.push_back(static_cast<std::uint8_t>(payload.size() >> 8));
  out.push_back(static_cast<std::uint8_t>(payload.size() & 0xFF));
  out.insert(out.end(), payload.begin(), payload.end());
  const std::uint32_t crc = crc24q({out.data() + start, out.size() - start});
  out.push_back(static_cast<std::uint8_t>(crc >> 16));
  out.push_back(static_cast<std::uint8_t>(crc >> 8));
  out.push_back(static_cast<std::uint8_t>(crc));
  return Ok{};
}

Result<std::vector<std::uint8_t>> frame_rtcm3(std::span<const std::uint8_t> payload) {
  std::vector<std::uint8_t> out;
  out.reserve(payload.size() + 6);
  if (Status s = append_frame(payload, out); !s.ok()) return s.error();
  return out;
}

int msm_message_number(Constellation system, int msm_type) {
  return message_base(system) + msm_type;
}

std::optional<MsmKind> msm_kind(int number) {
  for (const Constellation c : {Constellation::Gps, Constellation::Glonass, Constellation::Galileo, Constellation::Qzss,
                                Constellation::BeiDou}) {
    const int type = number - message_base(c);
    if (type >= 1 && type <= 7) return MsmKind{c, type};
  }
  return std::nullopt;
}

std::optional<core::SignalCode> msm_signal_code(Constellation system, int signal_id) {
  if (signal_id < 1 || signal_id > 32) return std::nullopt;
  const char* code = signal_table(system)[static_cast<std::size_t>(signal_id - 1)];
  if (code[0] == '\0') return std::nullopt;
  return core::SignalCode{code[0], code[1]};
}

std::optional<int> msm_signal_id(Constellation system, core::SignalCode code) {
  if (code.band < '0' || code.band > '9' || code.attribute < 'A' || code.attribute > 'Z') return std::nullopt;
  const int id = kSignalIds.ids[static_cast<std::size_t>(system)][code_slot(code.band, code.attribute)];
  if (id == 0) return std::nullopt;
  return id;
}

double msm_lock_time_ms(int indicator, bool extended) {
  if (!extended) {
    if (indicator <= 0) return 0.0;
    return static_cast<double>(std::int64_t{1} << (std::min(indicator, 15) + 4));  // 1 -> 32 ms ... 15 -> 524288 ms
  }
  if (indicator < 64) return std::max(indicator, 0);
  if (indicator >= 704) return 67108864.0;
  const int k = (indicator - 64) / 32 + 1;  // blocks of 32 indicators with a step of 2^k ms
  return static_cast<double>(static_cast<std::int64_t>(indicator - 32 * k) << k);
}

int msm_lock_indicator(double lock_time_ms, bool extended) {
  if (!(lock_time_ms > 0.0)) return 0;
  if (!extended) {
    if (lock_time_ms < 32.0) return 0;
    if (lock_time_ms >= 524288.0) return 15;
    const auto t = static_cast<std::uint64_t>(lock_time_ms);
    return std::clamp(static_cast<int>(std::bit_width(t)) - 1 - 4, 1, 15);  // floor(log2(t)) - 4
  }
  if (lock_time_ms >= 67108864.0) return 704;
  const auto t = static_cast<std::int64_t>(lock_time_ms);
  if (t < 64) return static_cast<int>(t);
  // Block k covers [64 * 2^(k-1), 64 * 2^k) with a step of 2^k.
  const int k = std::bit_width(static_cast<std::uint64_t>(t / 64));  // t / 64 in [2^(k-1), 2^k)
  return static_cast<int>(t >> k) + 32 * k;
}

core::GpsTime msm_epoch_time(Constellation system, std::uint32_t epoch_time, const core::GpsTime& reference,
                             const core::LeapSecondTable& leaps) {
  switch (system) {
    case Constellation::Gps:
    case Constellation::Galileo:
    case Constellation::Qzss: return core::nearest_gps_time(epoch_time * 1e-3, reference).normalized();
    case Constellation::BeiDou:
      return core::nearest_gps_time(epoch_time * 1e-3 - core::kBdtMinusGpstS, reference).normalized();
    case Constellation::Glonass: {
      const unsigned day = epoch_time >> 27;
      const double tod_s = (epoch_time & ((1U << 27) - 1)) * 1e-3;
      const double msk_minus_gps_s = core::kGlonassMinusUtcS - leaps.gps_minus_utc_at_gps(reference);
      if (day < 7) {
        return core::nearest_gps_time(day * double(core::kSecondsPerDay) + tod_s - msk_minus_gps_s, reference)
            .normalized();
      }
      // Day unknown: the instant of that time of day nearest the reference.
      const core::GpsTime guess = core::GpsTime{reference.week, tod_s - msk_minus_gps_s}.normalized();
      const double days = std::round((reference - guess) / core::kSecondsPerDay);
      return guess + days * core::kSecondsPerDay;
    }
  }
  return reference;
}

std::uint32_t msm_epoch_field(Constellation system, const core::GpsTime& time, const core::LeapSecondTable& leaps) {
  constexpr std::int64_t kWeekMs = std::int64_t{core::kSecondsPerWeek} * 1000;
  constexpr std::int64_t kDayMs = std::int64_t{core::kSecondsPerDay} * 1000;
  auto week_ms = [](const core::GpsTime& t) {
    const std::int64_t ms = std::llround(t.normalized().tow_s * 1000.0);
    return ((ms % kWeekMs) + kWeekMs) % kWeekMs;
  };
  switch (system) {
    case Constellation::Gps:
    case Constellation::Galileo:
    case Constellation::Qzss: return static_cast<std::uint32_t>(week_ms(time));
    case Constellation::BeiDou: return static_cast<std::uint32_t>(week_ms(time + core::kBdtMinusGpstS));
    case Constellation::Glonass: {
      const double msk_minus_gps_s = core::kGlonassMinusUtcS - leaps.gps_minus_utc_at_gps(time);
      const std::int64_t ms = week_ms(time + msk_minus_gps_s);
      return static_cast<std::uint32_t>(((ms / kDayMs) << 27) | (ms % kDayMs));
    }
  }
  return 0;
}

namespace {

/// A satellite to send: its rough range (2^-10 ms) and rough phase range rate (whole m/s).
struct SatPlan {
  const MsmSatellite* sat = nullptr;
  double rough_ms = 0.0;
  double rough_rate_mps = 0.0;
  bool rate_valid = false;
};
/// A cell to send, in satellite-major order.
struct CellPlan {
  const MsmCell* cell = nullptr;
  const SatPlan* sat = nullptr;
};

/// The satellites that have a rough range (the first pseudorange, else the first phase range), in satellite id order,
/// and the satellite and signal masks; the others are counted as dropped.
Status plan_satellites(const MsmMessage& message, const fields::MsmFields& f, std::vector<SatPlan>& sats,
                       fields::MsmMasks& masks, MsmEncodeReport& report) {
  const int number = masks.number;
  const double rough_lsb_ms = f.rough_range_frac.lsb;
  for (const MsmSatellite& s : message.satellites) {
    if (s.satellite_id < 1 || s.satellite_id > 64) {
      return Error{message_text(number) + ": satellite id " + std::to_string(s.satellite_id) + " outside 1-64"};
    }
    if ((masks.satellites & (std::uint64_t{1} << (64 - s.satellite_id))) != 0) {
      return Error{message_text(number) + ": satellite id " + std::to_string(s.satellite_id) + " given twice"};
    }
    SatPlan plan{&s};
    double rough_m = core::kNoValue;
    for (const MsmCell& c : s.cells) {
      if (core::has_value(c.pseudorange_m)) {
        rough_m = c.pseudorange_m;
        break;
      }
    }
    if (!core::has_value(rough_m)) {
      for (const MsmCell& c : s.cells) {
        if (core::has_value(c.phase_range_m)) {
          rough_m = c.phase_range_m;
          break;
        }
      }
    }
    const double rough_ms = std::floor(rough_m / kRangeMsM / rough_lsb_ms + 0.5) * rough_lsb_ms;
    if (!(rough_ms > 0.0 && rough_ms < kInvalidRoughInt)) {
      ++report.dropped_satellites;
      continue;
    }
    plan.rough_ms = rough_ms;
    for (const MsmCell& c : s.cells) {
      if (core::has_value(c.phase_range_rate_mps)) {
        plan.rough_rate_mps = std::floor(c.phase_range_rate_mps + 0.5);
        plan.rate_valid = std::abs(plan.rough_rate_mps) < 8192.0;
        break;
      }
    }
    for (const MsmCell& c : s.cells) {
      if (c.signal_id < 1 || c.signal_id > 32) {
        return Error{message_text(number) + ": signal id " + std::to_string(c.signal_id) + " outside 1-32"};
      }
      masks.signals |= 1U << (32 - c.signal_id);
    }
    masks.satellites |= std::uint64_t{1} << (64 - s.satellite_id);
    sats.push_back(plan);
  }
  std::sort(sats.begin(), sats.end(),
            [](const SatPlan& a, const SatPlan& b) { return a.sat->satellite_id < b.sat->satellite_id; });
  return Ok{};
}

/// The signal ids of a signal mask, in order.
std::array<int, 32> signal_ids_of(std::uint32_t signal_mask) {
  std::array<int, 32> ids{};
  int k = 0;
  for (int id = 1; id <= 32; ++id) {
    if ((signal_mask & (1U << (32 - id))) != 0) ids[static_cast<std::size_t>(k++)] = id;
  }
  return ids;
}

/// The cells of the planned satellites, satellite-major, and the cell mask; the number of cells.
Result<int> plan_cells(const std::vector<SatPlan>& sats, fields::MsmMasks& masks,
                       std::array<CellPlan, kMaxCells>& cells) {
  const int nsat = static_cast<int>(sats.size());
  const int nsig = std::popcount(masks.signals);
  const std::array<int, 32> signal_ids = signal_ids_of(masks.signals);
  int ncell = 0;
  int cell_bit = 0;
  for (const SatPlan& sp : sats) {
    for (int k = 0; k < nsig; ++k, ++cell_bit) {
      const MsmCell* found = nullptr;
      for (const MsmCell& c : sp.sat->cells) {
        if (c.signal_id == signal_ids[static_cast<std::size_t>(k)]) {
          if (found != nullptr) {
            return Error{message_text(masks.number) + ": signal id " + std::to_string(c.signal_id) +
                         " given twice for satellite " + std::to_string(sp.sat->satellite_id)};
          }
          found = &c;
        }
      }
      if (found != nullptr) {
        masks.cells |= std::uint64_t{1} << (nsat * nsig - 1 - cell_bit);
        cells[static_cast<std::size_t>(ncell++)] = CellPlan{found, &sp};
      }
    }
  }
  return ncell;
}

/// The satellite data of the planned satellites, as sent.
void pack_satellites(const fields::MsmFields& f, const std::vector<SatPlan>& sats,
                     std::span<fields::MsmSatelliteData> out) {
  for (std::size_t i = 0; i < sats.size(); ++i) {
    const SatPlan& sp = sats[i];
    const double whole_ms = std::floor(sp.rough_ms);
    out[i].rough_range_ms = static_cast<std::uint32_t>(whole_ms);
    out[i].info = static_cast<std::uint32_t>(sp.sat->extended_info & 0xF);
    out[i].rough_range_frac =
        static_cast<std::uint32_t>(std::lround((sp.rough_ms - whole_ms) / f.rough_range_frac.lsb));
    out[i].rough_rate =
        static_cast<std::int32_t>(sp.rate_valid ? static_cast<std::int64_t>(sp.rough_rate_mps) : kInvalidRate);
  }
}

/// The signal data of the planned cells, as sent: values that do not fit their field are sent invalid and counted.
void pack_cells(const fields::MsmFields& f, std::span<const CellPlan> cells, std::span<fields::MsmSignalData> out,
                MsmEncodeReport& report) {
  auto fine = [&](double value_m, double rough_ms, const fields::Field& field) -> std::int32_t {
    if (!core::has_value(value_m)) return static_cast<std::int32_t>(invalid_marker(field.bits));
    const auto q = fit_signed(value_m / kRangeMsM - rough_ms, field.lsb, field.bits);
    if (!q) {
      ++report.invalid_values;
      return static_cast<std::int32_t>(invalid_marker(field.bits));
    }
    return static_cast<std::int32_t>(*q);
  };
  const double max_cnr = static_cast<double>((1U << f.cnr.bits) - 1);
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const MsmCell& cell = *cells[i].cell;
    const SatPlan& sat = *cells[i].sat;
    fields::MsmSignalData& d = out[i];
    d.pseudorange = fine(cell.pseudorange_m, sat.rough_ms, f.pseudorange);
    d.phase_range = fine(cell.phase_range_m, sat.rough_ms, f.phase_range);
    d.lock_time = static_cast<std::uint32_t>(msm_lock_indicator(cell.lock_time_ms, f.high_resolution));
    d.half_cycle = cell.half_cycle;
    const double cnr = cell.cnr_dbhz;
    d.cnr = static_cast<std::uint32_t>(
        core::has_value(cnr) ? std::clamp(std::floor(cnr / f.cnr.lsb + 0.5), 1.0, max_cnr) : 0.0);
    d.fine_rate = static_cast<std::int32_t>(kInvalidFineRate);
    if (!f.extended) continue;
    if (core::has_value(cell.phase_range_rate_mps) && sat.rate_valid) {
      const auto q = fit_signed(cell.phase_range_rate_mps - sat.rough_rate_mps, f.fine_rate.lsb, f.fine_rate.bits);
      if (q) {
        d.fine_rate = static_cast<std::int32_t>(*q);
      } else {
        ++report.invalid_values;
      }
    } else if (core::has_value(cell.phase_range_rate_mps)) {
      ++report.invalid_values;
    }
  }
}

/// The satellites and cells of a decoded MSM from its masks and data as sent.
void unpack_msm(const fields::MsmFields& f, const fields::MsmMasks& masks,
                std::span<const fields::MsmSatelliteData> sat_data, std::span<const fields::MsmSignalData> cell_data,
                std::vector<MsmSatellite>& satellites) {
  const int nsat = static_cast<int>(sat_data.size());
  const int nsig = std::popcount(masks.signals);
  const std::array<int, 32> signal_ids = signal_ids_of(masks.signals);
  const std::int64_t pr_invalid = invalid_marker(f.pseudorange.bits);
  const std::int64_t ph_invalid = invalid_marker(f.phase_range.bits);
  satellites.resize(static_cast<std::size_t>(nsat));
  std::size_t k = 0;  // cell
  int id = 0;         // satellite id
  for (int i = 0; i < nsat; ++i) {
    while ((masks.satellites & (std::uint64_t{1} << (63 - id))) == 0) ++id;
    const fields::MsmSatelliteData& sd = sat_data[static_cast<std::size_t>(i)];
    MsmSatellite& s = satellites[static_cast<std::size_t>(i)];
    s.satellite_id = ++id;
    s.extended_info = f.extended ? static_cast<int>(sd.info) : 15;
    s.cells.clear();
    double rough_ms = sd.rough_range_ms == kInvalidRoughInt ? core::kNoValue : static_cast<int>(sd.rough_range_ms);
    rough_ms += static_cast<double>(sd.rough_range_frac) * f.rough_range_frac.lsb;
    const double rough_rate =
        f.extended && sd.rough_rate != kInvalidRate ? static_cast<double>(sd.rough_rate) : core::kNoValue;
    for (int g = 0; g < nsig; ++g) {
      if ((masks.cells & (std::uint64_t{1} << (nsat * nsig - 1 - (i * nsig + g)))) == 0) continue;
      const fields::MsmSignalData& d = cell_data[k++];
      MsmCell cell;
      cell.signal_id = signal_ids[static_cast<std::size_t>(g)];
      cell.pseudorange_m = d.pseudorange == pr_invalid
                               ? core::kNoValue
                               : (rough_ms + static_cast<double>(d.pseudorange) * f.pseudorange.lsb) * kRangeMsM;
      cell.phase_range_m = d.phase_range == ph_invalid
                               ? core::kNoValue
                               : (rough_ms + static_cast<double>(d.phase_range) * f.phase_range.lsb) * kRangeMsM;
      cell.lock_indicator = static_cast<int>(d.lock_time);
      cell.lock_time_ms = msm_lock_time_ms(cell.lock_indicator, f.high_resolution);
      cell.half_cycle = d.half_cycle;
      cell.cnr_dbhz = d.cnr == 0 ? core::kNoValue : static_cast<double>(d.cnr) * f.cnr.lsb;
      if (f.extended) {
        cell.phase_range_rate_mps = d.fine_rate == kInvalidFineRate
                                        ? core::kNoValue
                                        : rough_rate + static_cast<double>(d.fine_rate) * f.fine_rate.lsb;
      }
      s.cells.push_back(cell);
    }
  }
}

}  // namespace

Result<MsmEncodeReport> append_msm(const MsmMessage& message, std::vector<std::uint8_t>& out) {
  const MsmHeader& h = message.header;
  fields::MsmMasks masks;
  masks.number = msm_message_number(h.system, h.type);
  if (h.type < 4 || h.type > 7) return Error{message_text(masks.number) + ": only MSM4-MSM7 can be encoded"};
  const fields::MsmFields& f = fields::msm_fields(h.type);
  MsmEncodeReport report;
  std::vector<SatPlan> sats;
  sats.reserve(message.satellites.size());
  if (Status s = plan_satellites(message, f, sats, masks, report); !s.ok()) return s.error();
  const int nsat = static_cast<int>(sats.size());
  const int nsig = std::popcount(masks.signals);
  if (nsat * nsig > kMaxCells) {
    return Error{message_text(masks.number) + ": " + std::to_string(nsat) + " satellites x " + std::to_string(nsig) +
                 " signals exceed the 64-cell mask; split the satellites over several messages"};
  }
  std::array<CellPlan, kMaxCells> cells{};
  const Result<int> ncell = plan_cells(sats, masks, cells);
  if (!ncell.ok()) return ncell.error();
  const std::size_t total_bits = kMsmHeaderBits + static_cast<std::size_t>(nsat * nsig) +
                                 static_cast<std::size_t>(nsat) * f.satellite_bits +
                                 static_cast<std::size_t>(*ncell) * f.cell_bits;
  if ((total_bits + 7) / 8 > kMaxPayloadBytes) {
    return Error{message_text(masks.number) + ": " + std::to_string((total_bits + 7) / 8) + " bytes exceed 1023"};
  }
  std::array<fields::MsmSatelliteData, kMaxCells> sat_data;
  std::array<fields::MsmSignalData, kMaxCells> cell_data;
  const std::span<fields::MsmSatelliteData> sat_span(sat_data.data(), sats.size());
  const std::span<fields::MsmSignalData> cell_span(cell_data.data(), static_cast<std::size_t>(*ncell));
  pack_satellites(f, sats, sat_span);
  pack_cells(f, std::span<const CellPlan>(cells.data(), cell_span.size()), cell_span, report);

  const std::size_t start = out.size();
  out.resize(start + (total_bits + 7) / 8);
  FixedBitWriter bits(out.data() + start);
  fields::FieldWriter w(bits, masks.number);
  fields::msm_header_fields(w, h, masks);
  fields::msm_cell_mask_field(w, masks);
  fields::msm_data_fields(w, f, std::span<const fields::MsmSatelliteData>(sat_span),
                          std::span<const fields::MsmSignalData>(cell_span));
  bits.flush();
  report.cells = *ncell;
  return report;
}

Result<MsmMessage> decode_msm(std::span<const std::uint8_t> payload) {
  MsmMessage m;
  if (Status s = decode_msm(payload, m); !s.ok()) return s.error();
  return m;
}

Status decode_msm(std::span<const std::uint8_t> payload, MsmMessage& m) {
  const int number = message_number(payload);
  const auto kind = msm_kind(number);
  if (!kind) return Error{message_text(number) + " is not a Multiple Signal Message"};
  if (kind->type < 4) {
    return Error{message_text(number) + ": MSM" + std::to_string(kind->type) +
                 " carries no complete observables; only MSM4-MSM7 are decoded"};
  }
  fields::FieldReader r(payload);
  if (r.bits_left() < kMsmHeaderBits) {
    return Error{message_text(number) + ": " + std::to_string(payload.size()) + " bytes, shorter than an MSM header"};
  }
  MsmHeader& h = m.header;
  h = MsmHeader{};
  h.system = kind->system;
  h.type = kind->type;
  fields::MsmMasks masks;
  fields::msm_header_fields(r, h, masks);
  const int nsat = std::popcount(masks.satellites);
  const int nsig = std::popcount(masks.signals);
  if (nsat * nsig > kMaxCells) {
    return Error{message_text(number) + ": masks announce " + std::to_string(nsat) + " satellites x " +
                 std::to_string(nsig) + " signals, more than 64 cells"};
  }
  const int mask_bits = nsat * nsig;
  if (r.bits_left() < static_cast<std::size_t>(mask_bits)) {
    return Error{message_text(number) + ": payload ends inside the cell mask"};
  }
  fields::msm_cell_mask_field(r, masks);
  const int ncell = std::popcount(masks.cells);
  const fields::MsmFields& f = fields::msm_fields(h.type);
  const std::size_t needed =
      static_cast<std::size_t>(nsat) * f.satellite_bits + static_cast<std::size_t>(ncell) * f.cell_bits;
  if (r.bits_left() < needed) {
    return Error{message_text(number) + ": " + std::to_string(payload.size()) + " bytes, too short for " +
                 std::to_string(nsat) + " satellites and " + std::to_string(ncell) + " cells (needs " +
                 std::to_string((r.position() + needed + 7) / 8) + ")"};
  }
  std::array<fields::MsmSatelliteData, kMaxCells> sat_data;
  std::array<fields::MsmSignalData, kMaxCells> cell_data;
  const std::span<fields::MsmSatelliteData> sats(sat_data.data(), static_cast<std::size_t>(nsat));
  const std::span<fields::MsmSignalData> cells(cell_data.data(), static_cast<std::size_t>(ncell));
  fields::msm_data_fields(r, f, sats, cells);
  unpack_msm(f, masks, sats, cells, m.satellites);
  return Ok{};
}

}  // namespace canyon::io::rtcm3
