// The RTCM 3 stream of a base station (see rtcm3_station_stream.hpp).

#include "canyon/io/rtcm3_station_stream.hpp"

#include <cmath>

namespace canyon::io {
namespace {

constexpr double kKeplerLeadS = 7200.0;  // a record is usable from two hours before its toe
constexpr std::size_t kMaxWarnings = 20;

long long toe_key(const core::GpsTime& t) {
  return std::llround(t.seconds_since_epoch());
}

}  // namespace

std::string Rtcm3StationStreamOptions::validate() const {
  if (std::string e = encoder.validate(); !e.empty()) return e;
  if (!(station_interval_s >= 0.0)) return "station message interval must be >= 0 s";
  if (!(ephemeris_interval_s >= 0.0)) return "ephemeris interval must be >= 0 s";
  return {};
}

Rtcm3StationStream::Rtcm3StationStream(Rtcm3StationStreamOptions options)
    : options_(std::move(options)), encoder_(options_.encoder) {}

void Rtcm3StationStream::add_navigation(const core::NavigationData& nav) {
  kepler_.insert(kepler_.end(), nav.kepler.begin(), nav.kepler.end());
  glonass_.insert(glonass_.end(), nav.glonass.begin(), nav.glonass.end());
  for (const core::GlonassEphemeris& g : nav.glonass) encoder_.set_glonass_channel(g.sat.prn, g.frequency_channel);
}

void Rtcm3StationStream::update_current(const core::GpsTime& t) {
  for (const core::KeplerEphemeris& e : kepler_) {
    if (e.toe - t > kKeplerLeadS) continue;
    Slot& slot = slots_[{e.sat.index(), rtcm3::ephemeris_message_number(e)}];
    if (!slot.kepler || e.toe - slot.kepler->toe > 0.0) slot.kepler = e;
  }
  for (const core::GlonassEphemeris& g : glonass_) {
    Slot& slot = slots_[{g.sat.index(), 1020}];
    if (!slot.glonass || std::abs(g.toe - t) < std::abs(slot.glonass->toe - t)) slot.glonass = g;
  }
}

Result<std::vector<Rtcm3Frame>> Rtcm3StationStream::epoch(const core::ObsEpoch& epoch) {
  if (const std::string e = options_.validate(); !e.empty()) return Error{"RTCM 3 station stream: " + e};
  std::vector<Rtcm3Frame> frames;
  const core::GpsTime t = epoch.time;
  // Station messages.
  const bool station_due = !station_sent_at_ || (options_.station_interval_s > 0.0 &&
                                                 t - *station_sent_at_ >= options_.station_interval_s - 1e-6);
  if (station_due && (station_ || antenna_)) {
    if (station_) {
      auto f = encoder_.encode_station(*station_);
      if (!f) return f.error();
      f->epoch_time = t;
      frames.push_back(std::move(*f));
      ++report_.station_messages;
    }
    if (antenna_) {
      auto f = encoder_.encode_antenna(*antenna_);
      if (!f) return f.error();
      f->epoch_time = t;
      frames.push_back(std::move(*f));
      ++report_.station_messages;
    }
    station_sent_at_ = t;
  }
  // Ephemerides of the satellites of this epoch.
  if (options_.send_ephemerides) {
    update_current(t);
    for (const core::SatelliteObs& so : epoch.sats) {
      for (auto it = slots_.lower_bound({so.sat.index(), 0}); it != slots_.end() && it->first.first == so.sat.index();
           ++it) {
        Slot& slot = it->second;
        const long long key =
            slot.kepler ? toe_key(slot.kepler->toe) : (slot.glonass ? toe_key(slot.glonass->toe) : -1);
        if (key < 0) continue;
        const bool changed = key != slot.sent_key;
        const bool repeat = options_.ephemeris_interval_s > 0.0 && slot.sent_at &&
                            t - *slot.sent_at >= options_.ephemeris_interval_s - 1e-6;
        if (!changed && !repeat) continue;
        Result<Rtcm3Frame> f =
            slot.kepler ? encoder_.encode_ephemeris(*slot.kepler) : encoder_.encode_ephemeris(*slot.glonass);
        slot.sent_key = key;
        slot.sent_at = t;
        if (!f) {
          if (report_.warnings.size() < kMaxWarnings) report_.warnings.push_back(f.error().message);
          continue;
        }
        f->epoch_time = t;
        frames.push_back(std::move(*f));
        ++report_.ephemeris_messages;
      }
    }
  }
  // Observations.
  auto r = encoder_.encode_epoch(epoch, frames);
  if (!r) return r.error();
  Rtcm3EncodeReport& sum = report_.observations;
  sum.messages += r->messages;
  sum.cells += r->cells;
  sum.unsupported_signals += r->unsupported_signals;
  sum.invalid_values += r->invalid_values;
  sum.dropped_satellites += r->dropped_satellites;
  sum.phase_without_channel += r->phase_without_channel;
  sum.arc_restarts += r->arc_restarts;
  return frames;
}

}  // namespace canyon::io
