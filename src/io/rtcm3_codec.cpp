// RTCM 3 stream decoder and encoder (see rtcm3_codec.hpp).

#include "canyon/io/rtcm3_codec.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

namespace canyon::io {
namespace {

using core::Constellation;

constexpr double kSameEpochS = 5e-4;            // MSM epoch times are whole milliseconds
constexpr double kMaxPhaseOffsetM = 1100.0;     // MSM phase range field: +-2^-8 ms = +-1171 m around the rough range
constexpr double kLegacyPhaseRollCyc = 1500.0;  // legacy phase range fields roll over by 1500 cycles

std::string satellite_text(const core::SatelliteId& sat) {
  return sat.to_string();
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// Decoder.

Rtcm3Decoder::Rtcm3Decoder(Rtcm3DecoderOptions options)
    : options_(std::move(options)), reference_(options_.reference_time) {
  slot_of_.fill(-1);
  for (const auto& [slot, channel] : options_.glonass_channels) glonass_channel_[slot] = channel;
}

std::vector<std::pair<int, int>> Rtcm3Decoder::glonass_channels() const {
  return {glonass_channel_.begin(), glonass_channel_.end()};
}

void Rtcm3Decoder::warn_once(const std::string& text) {
  if (warned_.insert(text).second) warnings_.push_back(text);
}

std::optional<core::ObsEpoch> Rtcm3Decoder::pop_epoch() {
  if (ready_head_ >= ready_.size()) {
    ready_.clear();
    ready_head_ = 0;
    return std::nullopt;
  }
  return std::move(ready_[ready_head_++]);
}

void Rtcm3Decoder::flush() {
  complete_epoch();
}

void Rtcm3Decoder::complete_epoch() {
  if (!assembling_) return;
  for (const core::SatelliteObs& s : assembling_->sats) slot_of_[static_cast<std::size_t>(s.sat.index())] = -1;
  // Satellites whose every signal was dropped (e.g. GLONASS phase without channel and no pseudorange).
  std::erase_if(assembling_->sats, [](const core::SatelliteObs& s) { return s.signals.empty(); });
  std::sort(assembling_->sats.begin(), assembling_->sats.end(),
            [](const core::SatelliteObs& a, const core::SatelliteObs& b) { return a.sat < b.sat; });
  ready_.push_back(std::move(*assembling_));
  assembling_.reset();
}

void Rtcm3Decoder::begin_epoch(const core::GpsTime& time) {
  if (assembling_ && std::abs(assembling_->time - time) > kSameEpochS) complete_epoch();
  if (!assembling_) {
    assembling_ = core::ObsEpoch{};
    assembling_->time = time;
  }
  last_epoch_time_ = time;
  reference_ = time;
}

core::SatelliteObs& Rtcm3Decoder::satellite(const core::SatelliteId& sat) {
  int& slot = slot_of_[static_cast<std::size_t>(sat.index())];
  if (slot < 0) {
    slot = static_cast<int>(assembling_->sats.size());
    assembling_->sats.push_back(core::SatelliteObs{sat, {}});
  }
  return assembling_->sats[static_cast<std::size_t>(slot)];
}

std::uint8_t Rtcm3Decoder::lock_lli(const core::SatelliteId& sat, core::SignalCode code, double lock_ms,
                                    double upper_ms, const core::GpsTime& time) {
  LockState& state = locks_.at(sat, code);
  // The first phase of a signal starts an arc, as a lock time of zero does.
  bool slip = !state.seen || lock_ms <= 0.0 || lock_ms < state.lock_ms;
  // The lock started after the previous epoch (its upper bound does not reach back to it): lost in between.
  if (state.seen && (time - state.time) * 1000.0 >= upper_ms - 0.5) slip = true;
  state.lock_ms = lock_ms;
  state.time = time;
  state.seen = true;
  return slip ? core::kLliLossOfLock : 0;
}

Status Rtcm3Decoder::add_msm(const rtcm3::MsmMessage& msm, Message& out) {
  const rtcm3::MsmHeader& h = msm.header;
  const core::GpsTime time = rtcm3::msm_epoch_time(h.system, h.epoch_time, reference_, options_.leaps);
  out.epoch_time = time;
  out.station_id = h.station_id;
  begin_epoch(time);
  const bool extended_lock = h.type >= 6;
  // Code and wavelength of each signal id of this message (GLONASS: per satellite, below).
  struct SignalInfo {
    std::optional<core::SignalCode> code;
    std::optional<double> lambda_m;
    bool known = false;
  };
  std::array<SignalInfo, 33> info{};
  for (const rtcm3::MsmSatellite& s : msm.satellites) {
    core::SatelliteId sat{h.system, static_cast<std::uint8_t>(s.satellite_id)};
    if (!sat.valid()) {
      warn_once(std::string(core::constellation_name(h.system)) + " satellite id " + std::to_string(s.satellite_id) +
                " not supported, skipped");
      continue;
    }
    int channel = core::kNoGlonassChannel;
    if (h.system == Constellation::Glonass) {
      if (s.extended_info <= 13) glonass_channel_[sat.prn] = s.extended_info - 7;
      const auto it = glonass_channel_.find(sat.prn);
      if (it != glonass_channel_.end()) channel = it->second;
    }
    core::SatelliteObs& obs = satellite(sat);
    for (const rtcm3::MsmCell& c : s.cells) {
      SignalInfo& si = info[static_cast<std::size_t>(c.signal_id)];
      if (!si.known) {
        si.code = rtcm3::msm_signal_code(h.system, c.signal_id);
        if (si.code && h.system != Constellation::Glonass) si.lambda_m = core::wavelength_m(h.system, *si.code);
        si.known = true;
      }
      const std::optional<core::SignalCode>& code = si.code;
      if (!code) {
        warn_once(std::string(core::constellation_name(h.system)) + " MSM signal id " + std::to_string(c.signal_id) +
                  " is reserved, skipped");
        continue;
      }
      if (obs.find(*code) != nullptr) continue;  // the same signal twice in one epoch: keep the first
      core::SignalObs sig;
      sig.code = *code;
      sig.pseudorange_m = c.pseudorange_m;
      sig.snr_dbhz = c.cnr_dbhz;
      const std::optional<double> lambda =
          h.system == Constellation::Glonass ? core::wavelength_m(h.system, *code, channel) : si.lambda_m;
      if (lambda) {
        if (core::has_value(c.phase_range_m)) sig.carrier_phase_cyc = c.phase_range_m / *lambda;
        if (core::has_value(c.phase_range_rate_mps)) sig.doppler_hz = -c.phase_range_rate_mps / *lambda;
      } else if (core::has_value(c.phase_range_m)) {
        warn_once(satellite_text(sat) +
                  ": GLONASS frequency channel unknown, carrier phase and Doppler dropped "
                  "(send MSM5/MSM7 or 1020, or give the channels)");
      }
      if (core::has_value(sig.carrier_phase_cyc)) {
        const double upper_ms = rtcm3::msm_lock_time_ms(c.lock_indicator + 1, extended_lock);
        sig.lli = lock_lli(sat, *code, c.lock_time_ms, upper_ms, time);
        if (c.half_cycle) sig.lli |= core::kLliHalfCycle;
      }
      if (core::has_value(sig.pseudorange_m) || core::has_value(sig.carrier_phase_cyc) ||
          core::has_value(sig.doppler_hz)) {
        obs.signals.push_back(sig);
      }
    }
  }
  if (!h.multiple_message) complete_epoch();
  return Ok{};
}

Status Rtcm3Decoder::add_legacy(const rtcm3::LegacyObsMessage& m, Message& out) {
  core::GpsTime time;
  if (m.system == Constellation::Glonass) {
    time = rtcm3::msm_epoch_time(Constellation::Glonass, (7U << 27) | m.epoch_time, reference_, options_.leaps);
  } else {
    time = rtcm3::msm_epoch_time(Constellation::Gps, m.epoch_time, reference_, options_.leaps);
  }
  out.epoch_time = time;
  out.station_id = m.station_id;
  begin_epoch(time);
  for (const rtcm3::LegacySatellite& s : m.satellites) {
    int channel = core::kNoGlonassChannel;
    if (m.system == Constellation::Glonass) {
      glonass_channel_[s.sat.prn] = s.glonass_channel;
      channel = s.glonass_channel;
    }
    core::SatelliteObs& obs = satellite(s.sat);
    for (const rtcm3::LegacySignal& l : s.signals) {
      if (obs.find(l.code) != nullptr) continue;
      core::SignalObs sig;
      sig.code = l.code;
      sig.pseudorange_m = l.pseudorange_m;
      sig.snr_dbhz = l.cnr_dbhz;
      const auto lambda = core::wavelength_m(m.system, l.code, channel);
      if (lambda && core::has_value(l.phase_range_m)) {
        // Phase range minus the L1 pseudorange, in cycles: an encoder keeps it within its field by steps of 1500
        // cycles; keep it continuous with the previous epoch (within 750 cycles).
        double diff_cyc = (l.phase_range_m - l.phase_reference_m) / *lambda;
        LockState& state = locks_.at(s.sat, l.code);
        if (core::has_value(state.last_phase_cyc)) {
          diff_cyc += kLegacyPhaseRollCyc * std::round((state.last_phase_cyc - diff_cyc) / kLegacyPhaseRollCyc);
        }
        sig.carrier_phase_cyc = l.phase_reference_m / *lambda + diff_cyc;
        sig.lli = lock_lli(s.sat, l.code, l.lock_time_s * 1000.0, l.lock_upper_s * 1000.0, time);
        locks_.at(s.sat, l.code).last_phase_cyc = diff_cyc;
      }
      obs.signals.push_back(sig);
    }
  }
  if (!m.synchronous) complete_epoch();
  return Ok{};
}

bool Rtcm3Decoder::add_ephemeris_key(const core::SatelliteId& sat, const core::GpsTime& toe, int iod, int source) {
  const auto toe_s = static_cast<long long>(std::llround(toe.seconds_since_epoch()));
  return ephemeris_keys_.insert({static_cast<int>(sat.system), sat.prn, toe_s, iod, source}).second;
}

Result<Rtcm3Decoder::Message> Rtcm3Decoder::decode(std::span<const std::uint8_t> payload) {
  Message out;
  out.number = rtcm3::message_number(payload);
  const int n = out.number;
  if (rtcm3::msm_kind(n)) {
    if (Status s = rtcm3::decode_msm(payload, msm_); !s.ok()) return s.error();
    out.content = Content::Observations;
    if (Status s = add_msm(msm_, out); !s.ok()) return s.error();
  } else if (n == 1004 || n == 1012) {
    auto legacy = rtcm3::decode_legacy_obs(payload);
    if (!legacy) return legacy.error();
    out.content = Content::Observations;
    if (Status s = add_legacy(*legacy, out); !s.ok()) return s.error();
  } else if (n == 1005 || n == 1006) {
    auto station = rtcm3::decode_station_position(payload);
    if (!station) return station.error();
    out.content = Content::StationPosition;
    out.station_id = station->station_id;
    station_ = *station;
  } else if (n == 1007 || n == 1008 || n == 1033) {
    auto antenna = rtcm3::decode_antenna_info(payload);
    if (!antenna) return antenna.error();
    out.content = Content::AntennaInfo;
    out.station_id = antenna->station_id;
    antenna_ = *antenna;
  } else if (n == 1230) {
    auto biases = rtcm3::decode_glonass_biases(payload);
    if (!biases) return biases.error();
    out.content = Content::GlonassBiases;
    out.station_id = biases->station_id;
    biases_ = *biases;
  } else if (n == 1019 || n == 1042 || n == 1044 || n == 1045 || n == 1046) {
    auto eph = rtcm3::decode_kepler_ephemeris(payload, reference_);
    if (!eph) return eph.error();
    out.content = Content::Ephemeris;
    if (last_epoch_time_) eph->transmission_time = *last_epoch_time_;
    out.new_ephemeris = add_ephemeris_key(eph->sat, eph->toe, eph->iode, eph->data_source);
    if (out.new_ephemeris) nav_.kepler.push_back(*eph);
  } else if (n == 1020) {
    auto eph = rtcm3::decode_glonass_ephemeris(payload, reference_, options_.leaps);
    if (!eph) return eph.error();
    out.content = Content::Ephemeris;
    glonass_channel_[eph->sat.prn] = eph->frequency_channel;
    out.new_ephemeris = add_ephemeris_key(eph->sat, eph->toe, 0, 0);
    if (out.new_ephemeris) nav_.glonass.push_back(*eph);
  } else {
    out.content = Content::Unsupported;
  }
  ++counts_[n];
  return out;
}

// ---------------------------------------------------------------------------------------------------------------
// Encoder.

std::string Rtcm3EncoderOptions::validate() const {
  if (station_id < 0 || station_id > 4095) return "station id must be within 0-4095";
  if (msm_type < 4 || msm_type > 7) return "MSM type must be 4, 5, 6 or 7";
  return {};
}

Rtcm3Encoder::Rtcm3Encoder(Rtcm3EncoderOptions options) : options_(std::move(options)) {
  for (const auto& [slot, channel] : options_.glonass_channels) glonass_channel_[slot] = channel;
}

void Rtcm3Encoder::set_glonass_channel(int slot, int channel) {
  glonass_channel_[slot] = channel;
}

std::optional<double> Rtcm3Encoder::wavelength(Constellation system, core::SignalCode code, int channel) {
  if (system == Constellation::Glonass || code.band < '0' || code.band > '9' || code.attribute < 'A' ||
      code.attribute > 'Z') {
    return core::wavelength_m(system, code, channel);
  }
  double& cached = wavelength_m_[static_cast<std::size_t>(system)][static_cast<std::size_t>(code.band - '0') * 26 +
                                                                   static_cast<std::size_t>(code.attribute - 'A')];
  if (cached == 0.0) cached = core::wavelength_m(system, code).value_or(-1.0);
  if (cached < 0.0) return std::nullopt;
  return cached;
}

namespace {

Result<Rtcm3Frame> framed(int number, const std::vector<std::uint8_t>& payload) {
  Rtcm3Frame frame;
  frame.message_number = number;
  frame.bytes.reserve(payload.size() + 6);
  if (Status s = rtcm3::append_frame(payload, frame.bytes); !s.ok()) return s.error();
  return frame;
}

}  // namespace

Result<Rtcm3Frame> Rtcm3Encoder::encode_station(rtcm3::StationPosition station) const {
  station.station_id = options_.station_id;
  std::vector<std::uint8_t> payload;
  if (Status s = rtcm3::append_station_position(station, payload); !s.ok()) return s.error();
  return framed(station.antenna_height_m ? 1006 : 1005, payload);
}

Result<Rtcm3Frame> Rtcm3Encoder::encode_antenna(rtcm3::AntennaInfo info) const {
  info.station_id = options_.station_id;
  std::vector<std::uint8_t> payload;
  if (Status s = rtcm3::append_antenna_info(info, payload); !s.ok()) return s.error();
  return framed(1033, payload);
}

Result<Rtcm3Frame> Rtcm3Encoder::encode_glonass_biases(rtcm3::GlonassBiases biases) const {
  biases.station_id = options_.station_id;
  std::vector<std::uint8_t> payload;
  if (Status s = rtcm3::append_glonass_biases(biases, payload); !s.ok()) return s.error();
  return framed(1230, payload);
}

Result<Rtcm3Frame> Rtcm3Encoder::encode_ephemeris(const core::KeplerEphemeris& eph) const {
  std::vector<std::uint8_t> payload;
  if (Status s = rtcm3::append_kepler_ephemeris(eph, payload); !s.ok()) {
    return Error{eph.sat.to_string() + ": " + s.error().message};
  }
  return framed(rtcm3::ephemeris_message_number(eph), payload);
}

Result<Rtcm3Frame> Rtcm3Encoder::encode_ephemeris(const core::GlonassEphemeris& eph) {
  glonass_channel_[eph.sat.prn] = eph.frequency_channel;
  std::vector<std::uint8_t> payload;
  if (Status s = rtcm3::append_glonass_ephemeris(eph, options_.leaps, payload); !s.ok()) {
    return Error{eph.sat.to_string() + ": " + s.error().message};
  }
  return framed(1020, payload);
}

Result<Rtcm3EncodeReport> Rtcm3Encoder::encode_epoch(const core::ObsEpoch& epoch, std::vector<Rtcm3Frame>& out) {
  if (const std::string broken = options_.validate(); !broken.empty()) return Error{"RTCM 3 encoder: " + broken};
  Rtcm3EncodeReport report;
  const std::array<std::size_t, core::kNumConstellations> used = collect_satellites(epoch, report);
  const std::vector<PendingMessage> pending = split_into_messages(used);
  for (std::size_t i = 0; i < pending.size(); ++i) {
    if (Status s = emit_message(epoch.time, pending[i], i + 1 < pending.size(), out, report); !s) return s.error();
  }
  return report;
}

std::array<std::size_t, core::kNumConstellations> Rtcm3Encoder::collect_satellites(const core::ObsEpoch& epoch,
                                                                                   Rtcm3EncodeReport& report) {
  // Satellites per constellation, in satellite order; the scratch objects (and their cell storage) are reused.
  std::array<std::size_t, core::kNumConstellations> used{};
  for (const core::SatelliteObs& so : epoch.sats) {
    const Constellation system = so.sat.system;
    int channel = core::kNoGlonassChannel;
    if (system == Constellation::Glonass) {
      const auto it = glonass_channel_.find(so.sat.prn);
      if (it != glonass_channel_.end()) channel = it->second;
    }
    auto& slot = per_system_[static_cast<std::size_t>(system)];
    std::size_t& n = used[static_cast<std::size_t>(system)];
    if (n == slot.size()) slot.emplace_back();
    rtcm3::MsmSatellite& ms = slot[n];
    ms.cells.clear();
    ms.satellite_id = so.sat.prn;
    ms.extended_info = system == Constellation::Glonass ? (channel != core::kNoGlonassChannel ? channel + 7 : 15) : 0;
    // Reference range for new arcs: the first pseudorange of the satellite.
    double reference_m = core::kNoValue;
    for (const core::SignalObs& s : so.signals) {
      if (core::has_value(s.pseudorange_m)) {
        reference_m = s.pseudorange_m;
        break;
      }
    }
    for (const core::SignalObs& s : so.signals) {
      const auto id = rtcm3::msm_signal_id(system, s.code);
      if (!id) {
        ++report.unsupported_signals;
        continue;
      }
      ms.cells.push_back(make_cell(epoch.time, so.sat, s, *id, channel, reference_m, report));
    }
    if (!ms.cells.empty()) ++n;
  }
  return used;
}

rtcm3::MsmCell Rtcm3Encoder::make_cell(const core::GpsTime& t, const core::SatelliteId& sat, const core::SignalObs& s,
                                       int signal_id, int channel, double reference_m, Rtcm3EncodeReport& report) {
  rtcm3::MsmCell cell;
  cell.signal_id = signal_id;
  cell.pseudorange_m = s.pseudorange_m;
  cell.cnr_dbhz = s.snr_dbhz;
  cell.half_cycle = (s.lli & core::kLliHalfCycle) != 0;
  const std::optional<double> lambda = wavelength(sat.system, s.code, channel);
  if (core::has_value(s.carrier_phase_cyc) || core::has_value(s.doppler_hz)) {
    if (!lambda) ++report.phase_without_channel;
  }
  if (lambda && core::has_value(s.doppler_hz)) cell.phase_range_rate_mps = -s.doppler_hz * *lambda;
  if (lambda && core::has_value(s.carrier_phase_cyc) && core::has_value(reference_m)) {
    const double own_m = core::has_value(s.pseudorange_m) ? s.pseudorange_m : reference_m;
    Arc& arc = arcs_.at(sat, s.code);
    const bool slip = (s.lli & core::kLliLossOfLock) != 0;
    auto start_arc = [&]() {
      arc.offset_cyc = std::round(s.carrier_phase_cyc - own_m / *lambda);
      arc.start = t;
      arc.valid = true;
    };
    if (!arc.valid || slip) start_arc();
    double phase_m = (s.carrier_phase_cyc - arc.offset_cyc) * *lambda;
    if (std::abs(phase_m - reference_m) > kMaxPhaseOffsetM) {
      ++report.arc_restarts;
      start_arc();
      phase_m = (s.carrier_phase_cyc - arc.offset_cyc) * *lambda;
    }
    cell.phase_range_m = phase_m;
    cell.lock_time_ms = std::max(0.0, (t - arc.start) * 1000.0);
  } else if (const Arc* arc = arcs_.find(sat, s.code); arc != nullptr && arc->valid) {
    // No phase this epoch, but the arc goes on (no loss of lock reported): its lock time keeps growing.
    cell.lock_time_ms = std::max(0.0, (t - arc->start) * 1000.0);
  }
  return cell;
}

std::vector<Rtcm3Encoder::PendingMessage> Rtcm3Encoder::split_into_messages(
    const std::array<std::size_t, core::kNumConstellations>& used) {
  // Per constellation, satellites split so that each message has at most 64 cells.
  std::vector<PendingMessage> pending;
  pending.reserve(8);
  for (std::size_t k = 0; k < per_system_.size(); ++k) {
    auto& sats = per_system_[k];
    const std::size_t nsat = used[k];
    std::sort(
        sats.begin(), sats.begin() + static_cast<std::ptrdiff_t>(nsat),
        [](const rtcm3::MsmSatellite& a, const rtcm3::MsmSatellite& b) { return a.satellite_id < b.satellite_id; });
    std::size_t first = 0;
    while (first < nsat) {
      // Grow the chunk while satellites x union of signals fits 64 cells.
      std::uint32_t mask = 0;
      std::size_t count = 0;
      while (first + count < nsat) {
        std::uint32_t m = mask;
        for (const rtcm3::MsmCell& c : sats[first + count].cells) m |= 1U << (32 - c.signal_id);
        if (static_cast<int>(count + 1) * std::popcount(m) > 64) break;
        mask = m;
        ++count;
      }
      if (count == 0) count = 1;  // a satellite with more than 64 signals cannot exist (32 ids)
      pending.push_back(PendingMessage{static_cast<Constellation>(k), first, count});
      first += count;
    }
  }
  return pending;
}

Status Rtcm3Encoder::emit_message(const core::GpsTime& t, const PendingMessage& p, bool more_follow,
                                  std::vector<Rtcm3Frame>& out, Rtcm3EncodeReport& report) {
  rtcm3::MsmMessage& msm = msm_;
  msm.header = rtcm3::MsmHeader{};
  msm.header.system = p.system;
  msm.header.type = options_.msm_type;
  msm.header.station_id = options_.station_id;
  msm.header.epoch_time = rtcm3::msm_epoch_field(p.system, t, options_.leaps);
  msm.header.multiple_message = more_follow;
  auto& sats = per_system_[static_cast<std::size_t>(p.system)];
  msm.satellites.resize(p.count);
  for (std::size_t k = 0; k < p.count; ++k) msm.satellites[k] = sats[p.first + k];  // reuses cell storage
  payload_.clear();
  auto encoded = rtcm3::append_msm(msm, payload_);
  if (!encoded) return encoded.error();
  report.cells += encoded->cells;
  report.invalid_values += encoded->invalid_values;
  report.dropped_satellites += encoded->dropped_satellites;
  Rtcm3Frame frame;
  frame.message_number = rtcm3::msm_message_number(p.system, options_.msm_type);
  frame.epoch_time = t;
  frame.bytes.reserve(payload_.size() + 6);
  if (Status s = rtcm3::append_frame(payload_, frame.bytes); !s.ok()) return s.error();
  out.push_back(std::move(frame));
  ++report.messages;
  return Ok{};
}

}  // namespace canyon::io
