// RTCM 3 legacy observation messages 1004 (GPS L1/L2) and 1012 (GLONASS L1/L2), decode only (RTCM 10403.3 tables
// 3.5-5, 3.5-10 ff.).

#include "canyon/io/bits.hpp"
#include "canyon/io/rtcm3.hpp"

namespace canyon::io::rtcm3 {
namespace {

constexpr double kPrLsbM = 0.02;
constexpr double kPhaseLsbM = 0.0005;
constexpr double kCnrLsbDbhz = 0.25;
constexpr double kGpsAmbiguityM = 299792.458;  // DF014 unit: one light millisecond
constexpr double kGloAmbiguityM = 599584.916;  // DF044 unit: two light milliseconds
constexpr std::int64_t kInvalidPhase = -(1 << 19);
constexpr std::int64_t kInvalidL2Pr = -(1 << 13);

/// DF013/DF019 lock time indicator -> minimum lock time (s).
double legacy_lock_time_s(int i) {
  if (i < 24) return i;
  if (i < 48) return 2 * i - 24;
  if (i < 72) return 4 * i - 120;
  if (i < 96) return 8 * i - 408;
  if (i < 120) return 16 * i - 1176;
  if (i < 127) return 32 * i - 3096;
  return 937;
}

}  // namespace

Result<LegacyObsMessage> decode_legacy_obs(std::span<const std::uint8_t> payload) {
  const int number = message_number(payload);
  if (number != 1004 && number != 1012) return Error{"RTCM 3 message " + std::to_string(number) + " is not 1004/1012"};
  const bool glonass = number == 1012;
  const unsigned header_bits = glonass ? 61 : 64;
  const unsigned sat_bits = glonass ? 130 : 125;
  BitReader r(payload);
  if (r.bits_left() < header_bits)
    return Error{"RTCM 3 message " + std::to_string(number) + ": shorter than its header"};
  LegacyObsMessage m;
  m.system = glonass ? core::Constellation::Glonass : core::Constellation::Gps;
  r.skip(12);
  m.station_id = static_cast<int>(r.u(12));
  m.epoch_time = r.u32(glonass ? 27 : 30);
  m.synchronous = r.u(1) != 0;
  const auto nsat = static_cast<std::size_t>(r.u(5));
  r.skip(4);
  if (r.bits_left() < nsat * sat_bits) {
    return Error{"RTCM 3 message " + std::to_string(number) + ": " + std::to_string(payload.size()) +
                 " bytes, too short for " + std::to_string(nsat) + " satellites"};
  }
  for (std::size_t k = 0; k < nsat; ++k) {
    LegacySatellite s;
    const auto id = static_cast<int>(r.u(6));
    s.sat = core::SatelliteId{m.system, static_cast<std::uint8_t>(id)};
    const auto l1_code = static_cast<int>(r.u(1));
    if (glonass) s.glonass_channel = static_cast<int>(r.u(5)) - 7;
    const double pr1_raw = static_cast<double>(r.u(glonass ? 25 : 24)) * kPrLsbM;
    const std::int64_t ppr1 = r.s(20);
    const auto lock1 = static_cast<int>(r.u(7));
    const double ambiguity = static_cast<double>(r.u(glonass ? 7 : 8)) * (glonass ? kGloAmbiguityM : kGpsAmbiguityM);
    const auto cnr1 = static_cast<double>(r.u(8));
    const auto l2_code = static_cast<int>(r.u(2));
    const std::int64_t dpr2 = r.s(14);
    const std::int64_t ppr2 = r.s(20);
    const auto lock2 = static_cast<int>(r.u(7));
    const auto cnr2 = static_cast<double>(r.u(8));
    const double pr1 = pr1_raw + ambiguity;

    LegacySignal l1;
    l1.code = core::SignalCode{'1', l1_code != 0 ? 'P' : 'C'};
    l1.pseudorange_m = pr1;
    if (ppr1 != kInvalidPhase) l1.phase_range_m = pr1 + static_cast<double>(ppr1) * kPhaseLsbM;
    l1.phase_reference_m = pr1;
    if (cnr1 > 0) l1.cnr_dbhz = cnr1 * kCnrLsbDbhz;
    l1.lock_time_s = legacy_lock_time_s(lock1);
    l1.lock_upper_s = lock1 < 127 ? legacy_lock_time_s(lock1 + 1) : 1e9;
    s.signals.push_back(l1);

    LegacySignal l2;
    if (glonass) {
      l2.code = core::SignalCode{'2', l2_code != 0 ? 'P' : 'C'};
    } else {
      constexpr char kL2Attributes[4] = {'X', 'P', 'D', 'W'};
      l2.code = core::SignalCode{'2', kL2Attributes[l2_code & 3]};
    }
    if (dpr2 != kInvalidL2Pr) l2.pseudorange_m = pr1 + static_cast<double>(dpr2) * kPrLsbM;
    if (ppr2 != kInvalidPhase) l2.phase_range_m = pr1 + static_cast<double>(ppr2) * kPhaseLsbM;
    l2.phase_reference_m = pr1;
    if (cnr2 > 0) l2.cnr_dbhz = cnr2 * kCnrLsbDbhz;
    l2.lock_time_s = legacy_lock_time_s(lock2);
    l2.lock_upper_s = lock2 < 127 ? legacy_lock_time_s(lock2 + 1) : 1e9;
    if (core::has_value(l2.pseudorange_m) || core::has_value(l2.phase_range_m)) s.signals.push_back(l2);
    if (s.sat.valid()) m.satellites.push_back(std::move(s));
  }
  return m;
}

}  // namespace canyon::io::rtcm3
