// Observation epochs <-> messages (see observation_msgs.hpp).

#include "canyon/dds/observation_msgs.hpp"

#include <algorithm>
#include <cmath>

namespace canyon::dds {
namespace {

constexpr std::size_t kMaxSatellites = 128;  // idl/GnssObservation.idl bounds
constexpr std::size_t kMaxSignals = 16;

msg::SignalObservation to_msg(const core::SignalObs& s) {
  msg::SignalObservation m;
  m.band(s.code.band);
  m.code_attribute(s.code.attribute);
  m.pseudorange_m(s.pseudorange_m);
  m.carrier_phase_cyc(s.carrier_phase_cyc);
  m.doppler_hz(s.doppler_hz);
  m.snr_dbhz(s.snr_dbhz);
  m.lli(s.lli);
  return m;
}

}  // namespace

msg::GnssObservationEpoch to_msg(const core::ObsEpoch& epoch, std::uint64_t sequence_number,
                                 const std::string& receiver_id, std::int64_t ingest_monotonic_ns) {
  msg::GnssObservationEpoch m;
  m.sequence_number(sequence_number);
  m.receiver_id(receiver_id.substr(0, 64));
  m.gps_week(epoch.time.week);
  m.gps_tow_s(epoch.time.tow_s);
  m.epoch_flag(static_cast<std::uint8_t>(epoch.flag));
  m.receiver_clock_offset_s(epoch.receiver_clock_offset_s);
  m.ingest_monotonic_ns(ingest_monotonic_ns);
  std::vector<msg::SatelliteObservation> sats;
  for (const core::SatelliteObs& s : epoch.sats) {
    if (sats.size() == kMaxSatellites) break;
    msg::SatelliteObservation sat;
    sat.system(core::system_letter(s.sat.system));
    sat.prn(s.sat.prn);
    std::vector<msg::SignalObservation> signals;
    for (std::size_t k = 0; k < s.signals.size() && k < kMaxSignals; ++k) signals.push_back(to_msg(s.signals[k]));
    sat.signals(std::move(signals));
    sats.push_back(std::move(sat));
  }
  m.satellites(std::move(sats));
  return m;
}

Result<core::ObsEpoch> from_msg(const msg::GnssObservationEpoch& m) {
  const std::string which = "observation epoch " + std::to_string(m.sequence_number());
  if (m.satellites().size() > kMaxSatellites) return Error{which + ": more than 128 satellites"};
  if (m.gps_week() < 0 || m.gps_week() > 9999 || !(m.gps_tow_s() >= 0.0 && m.gps_tow_s() < 604800.0)) {
    return Error{which + ": GPS time out of range"};
  }
  if (m.epoch_flag() > static_cast<std::uint8_t>(core::EpochFlag::CycleSlipRecords)) {
    return Error{which + ": epoch flag " + std::to_string(m.epoch_flag()) + " (0-6)"};
  }
  core::ObsEpoch epoch;
  epoch.time = core::GpsTime{m.gps_week(), m.gps_tow_s()};
  epoch.flag = static_cast<core::EpochFlag>(m.epoch_flag());
  epoch.receiver_clock_offset_s = m.receiver_clock_offset_s();
  for (const msg::SatelliteObservation& s : m.satellites()) {
    const auto system = core::constellation_from_letter(s.system());
    core::SatelliteObs sat;
    if (system) sat.sat = core::SatelliteId{*system, s.prn()};
    if (!system || !sat.sat.valid()) {
      return Error{which + ": no satellite '" + std::string(1, s.system()) + std::to_string(s.prn()) + "'"};
    }
    if (s.signals().size() > kMaxSignals) return Error{which + ": more than 16 signals of " + sat.sat.to_string()};
    for (const msg::SignalObservation& g : s.signals()) {
      const auto code = core::parse_signal(std::string{g.band(), g.code_attribute()});
      if (!code) return Error{which + ": " + sat.sat.to_string() + " has no RINEX 3 signal '" + g.band() + "'"};
      core::SignalObs signal;
      signal.code = *code;
      signal.pseudorange_m = g.pseudorange_m();
      signal.carrier_phase_cyc = g.carrier_phase_cyc();
      signal.doppler_hz = g.doppler_hz();
      signal.snr_dbhz = g.snr_dbhz();
      signal.lli = g.lli();
      sat.signals.push_back(signal);
    }
    epoch.sats.push_back(std::move(sat));
  }
  return epoch;
}

}  // namespace canyon::dds
