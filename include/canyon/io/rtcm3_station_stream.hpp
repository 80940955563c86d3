#pragma once
// The RTCM 3 stream of a base station: observation epochs as MSM messages, the station position (1005/1006) and
// antenna descriptors (1033) at a configured interval, and the ephemerides of the satellites in view, each when it
// becomes current and again at a configured interval. Used by `canyon convert` (RINEX -> RTCM 3) and `canyon base`.
//
// An ephemeris is current for a satellite (and message type: Galileo I/NAV and F/NAV are separate) when it is the
// record of largest toe not later than the epoch plus two hours among those given (GLONASS: toe nearest the epoch).

#include <map>
#include <optional>
#include <vector>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/io/rtcm3.hpp"
#include "canyon/io/rtcm3_codec.hpp"

namespace canyon::io {

struct Rtcm3StationStreamOptions {
  Rtcm3EncoderOptions encoder;       ///< station id, MSM type, GLONASS channels
  double station_interval_s = 10.0;  ///< 1005/1006 (and 1033 when given) every this many seconds; 0: once at the start
  double ephemeris_interval_s = 60.0;  ///< each current ephemeris again every this many seconds; 0: only when new
  bool send_ephemerides = true;

  /// Empty if valid, else the violated rule.
  [[nodiscard]] std::string validate() const;
};

struct Rtcm3StationStreamReport {
  Rtcm3EncodeReport observations;  ///< summed over epochs
  int station_messages = 0;
  int ephemeris_messages = 0;
  std::vector<std::string> warnings;  ///< ephemerides that could not be encoded (first ones)
};

class Rtcm3StationStream {
 public:
  explicit Rtcm3StationStream(Rtcm3StationStreamOptions options);

  void set_station(const rtcm3::StationPosition& station) { station_ = station; }
  void set_antenna(const rtcm3::AntennaInfo& antenna) { antenna_ = antenna; }
  /// Adds navigation records (they become current when the stream reaches them).
  void add_navigation(const core::NavigationData& nav);

  /// The frames due at this epoch, in sending order: station messages, ephemerides, then the MSM messages.
  Result<std::vector<Rtcm3Frame>> epoch(const core::ObsEpoch& epoch);

  [[nodiscard]] const Rtcm3StationStreamReport& report() const { return report_; }
  [[nodiscard]] const Rtcm3StationStreamOptions& options() const { return options_; }

 private:
  struct Slot {
    std::optional<core::KeplerEphemeris> kepler;
    std::optional<core::GlonassEphemeris> glonass;
    std::optional<core::GpsTime> sent_at;
    long long sent_key = -1;  // toe of the record sent last
  };
  void update_current(const core::GpsTime& t);

  Rtcm3StationStreamOptions options_;
  Rtcm3Encoder encoder_;
  std::optional<rtcm3::StationPosition> station_;
  std::optional<rtcm3::AntennaInfo> antenna_;
  std::optional<core::GpsTime> station_sent_at_;
  std::vector<core::KeplerEphemeris> kepler_;
  std::vector<core::GlonassEphemeris> glonass_;
  std::map<std::pair<int, int>, Slot> slots_;  // (satellite index, message number)
  Rtcm3StationStreamReport report_;
};

}  // namespace canyon::io
