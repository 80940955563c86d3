#include "canyon/core/ephemeris.hpp"

namespace canyon::core {

void NavigationData::merge(const NavigationData& other) {
  kepler.insert(kepler.end(), other.kepler.begin(), other.kepler.end());
  glonass.insert(glonass.end(), other.glonass.begin(), other.glonass.end());
  if (!gps_klobuchar) gps_klobuchar = other.gps_klobuchar;
  if (!bds_klobuchar) bds_klobuchar = other.bds_klobuchar;
  if (!leap_seconds) leap_seconds = other.leap_seconds;
}

int NavigationData::glonass_channel(int slot) const {
  for (const GlonassEphemeris& e : glonass) {
    if (e.sat.prn == slot) return e.frequency_channel;
  }
  return kNoGlonassChannel;
}

}  // namespace canyon::core
