// RTCM 3 Multiple Signal Messages (RTCM 10403.3 section 3.5.12): header, satellite and signal data of MSM4-MSM7,
// signal ids, lock time indicators and epoch times; and the RTCM 3 frame (section 4).

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>

#include "canyon/io/bits.hpp"
#include "canyon/io/rtcm3.hpp"

namespace canyon::io::rtcm3 {
namespace {

using core::Constellation;

constexpr std::size_t kMsmHeaderBits = 169;  // without the cell mask
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

/// Field layout of an MSM type (4-7).
struct Layout {
  bool extended = false;   // extended satellite info and phase range rates (MSM5, MSM7)
  bool high_res = false;   // MSM6, MSM7
  unsigned pr_bits = 15;   // DF400 / DF405
  double pr_lsb_ms = 0.0;  // 2^-24 / 2^-29
  unsigned ph_bits = 22;   // DF401 / DF406
  double ph_lsb_ms = 0.0;  // 2^-29 / 2^-31
  unsigned lock_bits = 4;  // DF402 / DF407
  unsigned cnr_bits = 6;   // DF403 / DF408
  double cnr_lsb = 1.0;    // 1 / 2^-4 dB-Hz
  [[nodiscard]] unsigned sat_bits() const { return extended ? 36 : 18; }
  [[nodiscard]] unsigned cell_bits() const {
    return pr_bits + ph_bits + lock_bits + 1 + cnr_bits + (extended ? 15 : 0);
  }
};

Layout layout(int type) {
  Layout l;
  l.extended = type == 5 || type == 7;
  l.high_res = type >= 6;
  if (l.high_res) {
    l.pr_bits = 20;
    l.pr_lsb_ms = 1.0 / 536870912.0;  // 2^-29
    l.ph_bits = 24;
    l.ph_lsb_ms = 1.0 / 2147483648.0;  // 2^-31
    l.lock_bits = 10;
    l.cnr_bits = 10;
    l.cnr_lsb = 1.0 / 16.0;
  } else {
    l.pr_lsb_ms = 1.0 / 16777216.0;   // 2^-24
    l.ph_lsb_ms = 1.0 / 536870912.0;  // 2^-29
  }
  return l;
}

constexpr double kRoughLsbMs = 1.0 / 1024.0;       // DF398
constexpr int kInvalidRoughInt = 255;              // DF397
constexpr std::int64_t kInvalidRate = -8192;       // DF399
constexpr std::int64_t kInvalidFineRate = -16384;  // DF404
constexpr double kFineRateLsbMps = 1e-4;

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

Result<MsmEncodeReport> append_msm(const MsmMessage& message, std::vector<std::uint8_t>& out) {
  const MsmHeader& h = message.header;
  const int number = msm_message_number(h.system, h.type);
  if (h.type < 4 || h.type > 7) return Error{message_text(number) + ": only MSM4-MSM7 can be encoded"};
  const Layout l = layout(h.type);
  MsmEncodeReport report;

  // Rough range per satellite: the first pseudorange, else the first phase range, rounded to 2^-10 ms.
  struct SatPlan {
    const MsmSatellite* sat = nullptr;
    double rough_ms = 0.0;
    double rough_rate_mps = 0.0;
    bool rate_valid = false;
  };
  std::vector<SatPlan> sats;
  sats.reserve(message.satellites.size());
  std::uint64_t sat_mask = 0;
  std::uint32_t sig_mask = 0;
  for (const MsmSatellite& s : message.satellites) {
    if (s.satellite_id < 1 || s.satellite_id > 64) {
      return Error{message_text(number) + ": satellite id " + std::to_string(s.satellite_id) + " outside 1-64"};
    }
    if ((sat_mask & (std::uint64_t{1} << (64 - s.satellite_id))) != 0) {
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
    const double rough_ms = std::floor(rough_m / kRangeMsM / kRoughLsbMs + 0.5) * kRoughLsbMs;
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
      sig_mask |= 1U << (32 - c.signal_id);
    }
    sat_mask |= std::uint64_t{1} << (64 - s.satellite_id);
    sats.push_back(plan);
  }
  std::sort(sats.begin(), sats.end(),
            [](const SatPlan& a, const SatPlan& b) { return a.sat->satellite_id < b.sat->satellite_id; });
  const int nsat = static_cast<int>(sats.size());
  const int nsig = std::popcount(sig_mask);
  if (nsat * nsig > kMaxCells) {
    return Error{message_text(number) + ": " + std::to_string(nsat) + " satellites x " + std::to_string(nsig) +
                 " signals exceed the 64-cell mask; split the satellites over several messages"};
  }
  std::array<int, 32> signal_ids{};
  {
    int k = 0;
    for (int id = 1; id <= 32; ++id) {
      if ((sig_mask & (1U << (32 - id))) != 0) signal_ids[static_cast<std::size_t>(k++)] = id;
    }
  }
  // Cells in satellite-major order, and the cell mask.
  struct CellPlan {
    const MsmCell* cell;
    const SatPlan* sat;
  };
  std::array<CellPlan, kMaxCells> cells{};
  int ncell = 0;
  std::uint64_t cell_mask = 0;
  int cell_bit = 0;
  for (const SatPlan& sp : sats) {
    for (int k = 0; k < nsig; ++k, ++cell_bit) {
      const MsmCell* found = nullptr;
      for (const MsmCell& c : sp.sat->cells) {
        if (c.signal_id == signal_ids[static_cast<std::size_t>(k)]) {
          if (found != nullptr) {
            return Error{message_text(number) + ": signal id " + std::to_string(c.signal_id) +
                         " given twice for satellite " + std::to_string(sp.sat->satellite_id)};
          }
          found = &c;
        }
      }
      if (found != nullptr) {
        cell_mask |= std::uint64_t{1} << (nsat * nsig - 1 - cell_bit);
        cells[static_cast<std::size_t>(ncell++)] = CellPlan{found, &sp};
      }
    }
  }
  const std::size_t total_bits = kMsmHeaderBits + static_cast<std::size_t>(nsat * nsig) +
                                 static_cast<std::size_t>(nsat) * l.sat_bits() +
                                 static_cast<std::size_t>(ncell) * l.cell_bits();
  if ((total_bits + 7) / 8 > kMaxPayloadBytes) {
    return Error{message_text(number) + ": " + std::to_string((total_bits + 7) / 8) + " bytes exceed 1023"};
  }

  const std::size_t start = out.size();
  out.resize(start + (total_bits + 7) / 8);
  FixedBitWriter w(out.data() + start);
  w.u(static_cast<std::uint64_t>(number), 12);
  w.u(static_cast<std::uint64_t>(h.station_id & 0xFFF), 12);
  w.u(h.epoch_time & 0x3FFFFFFF, 30);
  w.u(h.multiple_message ? 1 : 0, 1);
  w.u(static_cast<std::uint64_t>(h.iods & 7), 3);
  w.u(0, 7);
  w.u(static_cast<std::uint64_t>(h.clock_steering & 3), 2);
  w.u(static_cast<std::uint64_t>(h.external_clock & 3), 2);
  w.u(h.divergence_free_smoothing ? 1 : 0, 1);
  w.u(static_cast<std::uint64_t>(h.smoothing_interval & 7), 3);
  w.u(sat_mask, 64);
  w.u(sig_mask, 32);
  w.u(cell_mask, static_cast<unsigned>(nsat * nsig));

  // Satellite data, field by field.
  for (const SatPlan& sp : sats) w.u(static_cast<std::uint64_t>(std::floor(sp.rough_ms)), 8);
  if (l.extended) {
    for (const SatPlan& sp : sats) w.u(static_cast<std::uint64_t>(sp.sat->extended_info & 0xF), 4);
  }
  for (const SatPlan& sp : sats) {
    w.u(static_cast<std::uint64_t>(std::lround((sp.rough_ms - std::floor(sp.rough_ms)) / kRoughLsbMs)), 10);
  }
  if (l.extended) {
    for (const SatPlan& sp : sats) w.s(sp.rate_valid ? static_cast<std::int64_t>(sp.rough_rate_mps) : kInvalidRate, 14);
  }

  // Signal data, field by field.
  auto fine = [&](double value_m, double rough_ms, double lsb_ms, unsigned bits) -> std::int64_t {
    if (!core::has_value(value_m)) return invalid_marker(bits);
    const auto q = fit_signed(value_m / kRangeMsM - rough_ms, lsb_ms, bits);
    if (!q) {
      ++report.invalid_values;
      return invalid_marker(bits);
    }
    return *q;
  };
  for (int i = 0; i < ncell; ++i) {
    const CellPlan& c = cells[static_cast<std::size_t>(i)];
    w.s(fine(c.cell->pseudorange_m, c.sat->rough_ms, l.pr_lsb_ms, l.pr_bits), l.pr_bits);
  }
  for (int i = 0; i < ncell; ++i) {
    const CellPlan& c = cells[static_cast<std::size_t>(i)];
    w.s(fine(c.cell->phase_range_m, c.sat->rough_ms, l.ph_lsb_ms, l.ph_bits), l.ph_bits);
  }
  for (int i = 0; i < ncell; ++i) {
    w.u(static_cast<std::uint64_t>(
            msm_lock_indicator(cells[static_cast<std::size_t>(i)].cell->lock_time_ms, l.high_res)),
        l.lock_bits);
  }
  for (int i = 0; i < ncell; ++i) w.u(cells[static_cast<std::size_t>(i)].cell->half_cycle ? 1 : 0, 1);
  const double max_cnr = static_cast<double>((1U << l.cnr_bits) - 1);
  for (int i = 0; i < ncell; ++i) {
    const double cnr = cells[static_cast<std::size_t>(i)].cell->cnr_dbhz;
    const double q = core::has_value(cnr) ? std::clamp(std::floor(cnr / l.cnr_lsb + 0.5), 1.0, max_cnr) : 0.0;
    w.u(static_cast<std::uint64_t>(q), l.cnr_bits);
  }
  if (l.extended) {
    for (int i = 0; i < ncell; ++i) {
      const CellPlan& c = cells[static_cast<std::size_t>(i)];
      std::int64_t q = kInvalidFineRate;
      if (core::has_value(c.cell->phase_range_rate_mps) && c.sat->rate_valid) {
        const auto f = fit_signed(c.cell->phase_range_rate_mps - c.sat->rough_rate_mps, kFineRateLsbMps, 15);
        if (f) {
          q = *f;
        } else {
          ++report.invalid_values;
        }
      } else if (core::has_value(c.cell->phase_range_rate_mps)) {
        ++report.invalid_values;
      }
      w.s(q, 15);
    }
  }
  w.flush();
  report.cells = ncell;
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
  BitReader r(payload);
  if (r.bits_left() < kMsmHeaderBits) {
    return Error{message_text(number) + ": " + std::to_string(payload.size()) + " bytes, shorter than an MSM header"};
  }
  MsmHeader& h = m.header;
  h = MsmHeader{};
  h.system = kind->system;
  h.type = kind->type;
  r.skip(12);
  h.station_id = static_cast<int>(r.u(12));
  h.epoch_time = r.u32(30);
  h.multiple_message = r.u(1) != 0;
  h.iods = static_cast<int>(r.u(3));
  r.skip(7);
  h.clock_steering = static_cast<int>(r.u(2));
  h.external_clock = static_cast<int>(r.u(2));
  h.divergence_free_smoothing = r.u(1) != 0;
  h.smoothing_interval = static_cast<int>(r.u(3));
  const std::uint64_t sat_mask = r.u(64);
  const auto sig_mask = static_cast<std::uint32_t>(r.u(32));
  const int nsat = std::popcount(sat_mask);
  const int nsig = std::popcount(sig_mask);
  if (nsat * nsig > kMaxCells) {
    return Error{message_text(number) + ": masks announce " + std::to_string(nsat) + " satellites x " +
                 std::to_string(nsig) + " signals, more than 64 cells"};
  }
  const int mask_bits = nsat * nsig;
  if (r.bits_left() < static_cast<std::size_t>(mask_bits)) {
    return Error{message_text(number) + ": payload ends inside the cell mask"};
  }
  const std::uint64_t cell_mask = r.u(static_cast<unsigned>(mask_bits));
  const int ncell = std::popcount(cell_mask);
  const Layout l = layout(h.type);
  const std::size_t needed =
      static_cast<std::size_t>(nsat) * l.sat_bits() + static_cast<std::size_t>(ncell) * l.cell_bits();
  if (r.bits_left() < needed) {
    return Error{message_text(number) + ": " + std::to_string(payload.size()) + " bytes, too short for " +
                 std::to_string(nsat) + " satellites and " + std::to_string(ncell) + " cells (needs " +
                 std::to_string((r.position() + needed + 7) / 8) + ")"};
  }
  std::array<int, 32> signal_ids{};
  {
    int k = 0;
    for (int id = 1; id <= 32; ++id) {
      if ((sig_mask & (1U << (32 - id))) != 0) signal_ids[static_cast<std::size_t>(k++)] = id;
    }
  }
  m.satellites.resize(static_cast<std::size_t>(nsat));
  for (MsmSatellite& s : m.satellites) {
    s.extended_info = 15;
    s.cells.clear();
  }
  std::array<double, 64> rough_ms{};
  std::array<double, 64> rough_rate{};
  {
    int k = 0;
    for (int id = 1; id <= 64; ++id) {
      if ((sat_mask & (std::uint64_t{1} << (64 - id))) != 0)
        m.satellites[static_cast<std::size_t>(k++)].satellite_id = id;
    }
  }
  for (int i = 0; i < nsat; ++i) {
    const auto v = static_cast<int>(r.u(8));
    rough_ms[static_cast<std::size_t>(i)] = v == kInvalidRoughInt ? core::kNoValue : v;
  }
  if (l.extended) {
    for (int i = 0; i < nsat; ++i) m.satellites[static_cast<std::size_t>(i)].extended_info = static_cast<int>(r.u(4));
  }
  for (int i = 0; i < nsat; ++i) rough_ms[static_cast<std::size_t>(i)] += static_cast<double>(r.u(10)) * kRoughLsbMs;
  if (l.extended) {
    for (int i = 0; i < nsat; ++i) {
      const std::int64_t v = r.s(14);
      rough_rate[static_cast<std::size_t>(i)] = v == kInvalidRate ? core::kNoValue : static_cast<double>(v);
    }
  }
  // Cells, satellite-major.
  std::array<int, 64> cell_sat{};
  {
    int k = 0;
    for (int s = 0; s < nsat; ++s) {
      for (int g = 0; g < nsig; ++g) {
        if ((cell_mask & (std::uint64_t{1} << (nsat * nsig - 1 - (s * nsig + g)))) == 0) continue;
        cell_sat[static_cast<std::size_t>(k)] = s;
        MsmCell cell;
        cell.signal_id = signal_ids[static_cast<std::size_t>(g)];
        m.satellites[static_cast<std::size_t>(s)].cells.push_back(cell);
        ++k;
      }
    }
  }
  // Cell pointers in transmission order.
  std::array<MsmCell*, 64> cell_ptr{};
  {
    int k = 0;
    for (MsmSatellite& s : m.satellites) {
      for (MsmCell& c : s.cells) cell_ptr[static_cast<std::size_t>(k++)] = &c;
    }
  }
  const std::int64_t pr_invalid = invalid_marker(l.pr_bits);
  const std::int64_t ph_invalid = invalid_marker(l.ph_bits);
  for (int i = 0; i < ncell; ++i) {
    const std::int64_t v = r.s(l.pr_bits);
    const double rough = rough_ms[static_cast<std::size_t>(cell_sat[static_cast<std::size_t>(i)])];
    cell_ptr[static_cast<std::size_t>(i)]->pseudorange_m =
        v == pr_invalid ? core::kNoValue : (rough + static_cast<double>(v) * l.pr_lsb_ms) * kRangeMsM;
  }
  for (int i = 0; i < ncell; ++i) {
    const std::int64_t v = r.s(l.ph_bits);
    const double rough = rough_ms[static_cast<std::size_t>(cell_sat[static_cast<std::size_t>(i)])];
    cell_ptr[static_cast<std::size_t>(i)]->phase_range_m =
        v == ph_invalid ? core::kNoValue : (rough + static_cast<double>(v) * l.ph_lsb_ms) * kRangeMsM;
  }
  for (int i = 0; i < ncell; ++i) {
    const auto indicator = static_cast<int>(r.u(l.lock_bits));
    cell_ptr[static_cast<std::size_t>(i)]->lock_indicator = indicator;
    cell_ptr[static_cast<std::size_t>(i)]->lock_time_ms = msm_lock_time_ms(indicator, l.high_res);
  }
  for (int i = 0; i < ncell; ++i) cell_ptr[static_cast<std::size_t>(i)]->half_cycle = r.u(1) != 0;
  for (int i = 0; i < ncell; ++i) {
    const std::uint64_t v = r.u(l.cnr_bits);
    cell_ptr[static_cast<std::size_t>(i)]->cnr_dbhz = v == 0 ? core::kNoValue : static_cast<double>(v) * l.cnr_lsb;
  }
  if (l.extended) {
    for (int i = 0; i < ncell; ++i) {
      const std::int64_t v = r.s(15);
      const double rough = rough_rate[static_cast<std::size_t>(cell_sat[static_cast<std::size_t>(i)])];
      cell_ptr[static_cast<std::size_t>(i)]->phase_range_rate_mps =
          v == kInvalidFineRate ? core::kNoValue : rough + static_cast<double>(v) * kFineRateLsbMps;
    }
  }
  return Ok{};
}

}  // namespace canyon::io::rtcm3
