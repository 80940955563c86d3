// RTCM 3 legacy observation messages 1004 (GPS L1/L2) and 1012 (GLONASS L1/L2), decode only (RTCM 10403.3 tables
// 3.5-5, 3.5-10 ff.; fields in rtcm3_fields.hpp).

#include "canyon/io/rtcm3.hpp"
#include "canyon/io/rtcm3_fields.hpp"

namespace canyon::io::rtcm3 {
namespace {

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

/// The satellite's signals from what its part of the message carried.
LegacySatellite legacy_satellite(const fields::LegacySatelliteWire& w, core::Constellation system) {
  const bool glonass = system == core::Constellation::Glonass;
  LegacySatellite s;
  s.sat = core::SatelliteId{system, static_cast<std::uint8_t>(w.id)};
  if (glonass) s.glonass_channel = w.channel - 7;
  const double pr1 = w.l1_pseudorange_m + w.ambiguity_m;

  LegacySignal l1;
  l1.code = core::SignalCode{'1', w.l1_code != 0 ? 'P' : 'C'};
  l1.pseudorange_m = pr1;
  if (w.l1_phase != kInvalidPhase) l1.phase_range_m = pr1 + static_cast<double>(w.l1_phase) * fields::kLegacyPhaseLsbM;
  l1.phase_reference_m = pr1;
  if (w.l1_cnr > 0) l1.cnr_dbhz = static_cast<double>(w.l1_cnr) * fields::kLegacyCnrLsbDbhz;
  l1.lock_time_s = legacy_lock_time_s(w.l1_lock);
  l1.lock_upper_s = w.l1_lock < 127 ? legacy_lock_time_s(w.l1_lock + 1) : 1e9;
  s.signals.push_back(l1);

  LegacySignal l2;
  if (glonass) {
    l2.code = core::SignalCode{'2', w.l2_code != 0 ? 'P' : 'C'};
  } else {
    constexpr char kL2Attributes[4] = {'X', 'P', 'D', 'W'};
    l2.code = core::SignalCode{'2', kL2Attributes[w.l2_code & 3]};
  }
  if (w.l2_pseudorange != kInvalidL2Pr) {
    l2.pseudorange_m = pr1 + static_cast<double>(w.l2_pseudorange) * fields::kLegacyPseudorangeLsbM;
  }
  if (w.l2_phase != kInvalidPhase) l2.phase_range_m = pr1 + static_cast<double>(w.l2_phase) * fields::kLegacyPhaseLsbM;
  l2.phase_reference_m = pr1;
  if (w.l2_cnr > 0) l2.cnr_dbhz = static_cast<double>(w.l2_cnr) * fields::kLegacyCnrLsbDbhz;
  l2.lock_time_s = legacy_lock_time_s(w.l2_lock);
  l2.lock_upper_s = w.l2_lock < 127 ? legacy_lock_time_s(w.l2_lock + 1) : 1e9;
  if (core::has_value(l2.pseudorange_m) || core::has_value(l2.phase_range_m)) s.signals.push_back(l2);
  return s;
}

}  // namespace

Result<LegacyObsMessage> decode_legacy_obs(std::span<const std::uint8_t> payload) {
  fields::LegacyWire wire;
  wire.number = message_number(payload);
  const int number = wire.number;
  if (number != 1004 && number != 1012) return Error{"RTCM 3 message " + std::to_string(number) + " is not 1004/1012"};
  const bool glonass = number == 1012;
  LegacyObsMessage m;
  m.system = glonass ? core::Constellation::Glonass : core::Constellation::Gps;
  fields::FieldCounter header_bits;
  fields::legacy_header_fields(header_bits, m, wire);
  fields::LegacySatelliteWire sat;
  fields::FieldCounter sat_bits;
  fields::legacy_satellite_fields(sat_bits, glonass, sat);
  if (8 * payload.size() < header_bits.bits())
    return Error{"RTCM 3 message " + std::to_string(number) + ": shorter than its header"};
  fields::FieldReader r(payload);
  fields::legacy_header_fields(r, m, wire);
  const auto nsat = static_cast<std::size_t>(wire.satellites);
  if (r.bits_left() < nsat * sat_bits.bits()) {
    return Error{"RTCM 3 message " + std::to_string(number) + ": " + std::to_string(payload.size()) +
                 " bytes, too short for " + std::to_string(nsat) + " satellites"};
  }
  for (std::size_t k = 0; k < nsat; ++k) {
    fields::legacy_satellite_fields(r, glonass, sat);
    LegacySatellite s = legacy_satellite(sat, m.system);
    if (s.sat.valid()) m.satellites.push_back(std::move(s));
  }
  return m;
}

}  // namespace canyon::io::rtcm3
