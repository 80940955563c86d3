#pragma once
// u-blox UBX messages (u-blox 8 / M8 and F9 interface descriptions): RXM-RAWX (raw measurements), RXM-SFRBX
// (navigation words), NAV-PVT and NAV-TIMEGPS; framing and checksum are in stream_framer.hpp, frame_ubx() builds a
// packet. UbxDecoder turns a receiver's packets into core::ObsEpoch and core::NavigationData, the structures the
// RINEX readers fill.
//
// RXM-RAWX -> ObsEpoch (time tag: rcvTow, week; GPST):
//  - pseudorange if trkStat bit 0 (prValid); carrier phase if trkStat bit 1 (cpValid) and cpStdev <= 5 (0.02 cycle);
//    Doppler and C/N0 always. Signals: RAWX version 0 (u-blox 8) has no signal id: GPS/QZSS/GLONASS L1 C/A "1C",
//    Galileo E1 "1X", BeiDou B1I "2I"; version 1 (F9) maps sigId (GPS L1C/A 1C, L2CL 2L, L2CM 2S, L5I 5I, L5Q 5Q;
//    Galileo E1C 1C, E1B 1B, E5aI 5I, E5aQ 5Q, E5bI 7I, E5bQ 7Q; BeiDou B1I 2I, B2I 7I, B1Cp 1P, B2ap 5P; QZSS L1C/A
//    1C, L1S 1Z, L2CM 2S, L2CL 2L, L5I 5I, L5Q 5Q; GLONASS L1OF 1C, L2OF 2C). SBAS and IRNSS measurements are skipped.
//  - Loss of lock (LLI bit 0) at a signal's first epoch, when the lock time is 0 or smaller than at the previous
//    epoch, or when the half-cycle subtraction state (trkStat bit 3) changed; a slip seen while the phase is invalid is
//    kept for the next valid phase. LLI bit 1 (half cycle unresolved) when trkStat bit 2 (halfCyc valid) is clear.
//  - GLONASS FDMA channel: freqId - 7.
// RXM-SFRBX -> ephemerides through the assemblers of nav_message.hpp: GPS/QZSS LNAV, GLONASS strings, Galileo I/NAV,
// BeiDou D1 (GEO D2 pages are skipped). The receiver time of the last RAWX (or NAV-TIMEGPS) resolves weeks.

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/observation.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/time.hpp"
#include "canyon/io/nav_message.hpp"

namespace canyon::io::ubx {

inline constexpr std::uint8_t kClassNav = 0x01;
inline constexpr std::uint8_t kClassRxm = 0x02;
inline constexpr std::uint8_t kIdNavPvt = 0x07;
inline constexpr std::uint8_t kIdNavTimeGps = 0x20;
inline constexpr std::uint8_t kIdRxmRawx = 0x15;
inline constexpr std::uint8_t kIdRxmSfrbx = 0x13;

/// A whole UBX packet: sync, class, id, length, payload, checksum.
[[nodiscard]] std::vector<std::uint8_t> frame_ubx(std::uint8_t cls, std::uint8_t id,
                                                  std::span<const std::uint8_t> payload);

/// u-blox gnssId/svId -> satellite (nullopt for SBAS, IRNSS or a number out of range).
[[nodiscard]] std::optional<core::SatelliteId> satellite(int gnss_id, int sv_id);
/// Signal of a measurement: RAWX version 0 has no sigId (L1 of each system); version >= 1 maps the sigId.
[[nodiscard]] std::optional<core::SignalCode> signal_code(int gnss_id, int sig_id, int rawx_version);

struct RawxMeasurement {
  double pseudorange_m = 0.0;
  double carrier_phase_cyc = 0.0;
  double doppler_hz = 0.0;
  int gnss_id = 0;
  int sv_id = 0;
  int sig_id = 0;
  int freq_id = 0;       ///< GLONASS: channel + 7
  int lock_time_ms = 0;  ///< carrier phase lock time (ms, capped at 64500)
  int cno_dbhz = 0;
  double pr_stdev_m = 0.0;  ///< 0.01 * 2^n m
  int cp_stdev = 0;         ///< 0.004 cycle units (4 bits)
  double do_stdev_hz = 0.0;
  std::uint8_t trk_stat = 0;  ///< bit 0 prValid, 1 cpValid, 2 halfCyc valid, 3 subHalfCyc
};
struct Rawx {
  double rcv_tow_s = 0.0;
  int week = 0;
  int leap_s = 0;
  std::uint8_t rec_stat = 0;  ///< bit 0 leapSec valid, bit 1 clock reset
  int version = 0;
  std::vector<RawxMeasurement> measurements;
};
Result<Rawx> decode_rawx(std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> encode_rawx(const Rawx& rawx);  ///< payload (tests, simulators)

struct Sfrbx {
  int gnss_id = 0;
  int sv_id = 0;
  int sig_id = 0;
  int freq_id = 0;
  int version = 0;
  std::vector<std::uint32_t> words;
};
Result<Sfrbx> decode_sfrbx(std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> encode_sfrbx(const Sfrbx& sfrbx);  ///< payload (tests)

/// NAV-PVT (92 bytes).
struct NavPvt {
  std::uint32_t itow_ms = 0;
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  std::uint8_t valid = 0;  ///< bit 0 date, 1 time, 2 fully resolved
  std::int32_t nano_ns = 0;
  int fix_type = 0;        ///< 0 none, 2 2D, 3 3D, 4 GNSS + dead reckoning, 5 time only
  std::uint8_t flags = 0;  ///< bit 0 gnssFixOK; bits 6-7 carrier solution (1 float, 2 fixed)
  int num_sv = 0;
  double lon_deg = 0.0, lat_deg = 0.0;
  double height_m = 0.0;  ///< above the ellipsoid
  double height_msl_m = 0.0;
  double h_acc_m = 0.0, v_acc_m = 0.0;
  double vel_ned_mps[3] = {0.0, 0.0, 0.0};
  double pdop = 0.0;
};
Result<NavPvt> decode_nav_pvt(std::span<const std::uint8_t> payload);

/// NAV-TIMEGPS (16 bytes).
struct NavTimeGps {
  std::uint32_t itow_ms = 0;
  std::int32_t ftow_ns = 0;
  int week = 0;
  int leap_s = 0;
  std::uint8_t valid = 0;  ///< bit 0 towValid, 1 weekValid, 2 leapSValid
  std::uint32_t t_acc_ns = 0;
  /// GPST of the navigation epoch (iTOW + fTOW).
  [[nodiscard]] core::GpsTime time() const { return core::GpsTime{week, itow_ms * 1e-3 + ftow_ns * 1e-9}.normalized(); }
};
Result<NavTimeGps> decode_nav_timegps(std::span<const std::uint8_t> payload);

}  // namespace canyon::io::ubx

namespace canyon::io {

struct UbxDecoderOptions {
  core::LeapSecondTable leaps = core::builtin_leap_seconds();
  /// GPST before the first RAWX or NAV-TIMEGPS (resolves navigation-word weeks until then); unset: words before
  /// the first time fix are dropped.
  std::optional<core::GpsTime> reference_time;
};

class UbxDecoder {
 public:
  enum class Content : std::uint8_t { Observations, NavigationWords, NavPvt, NavTimeGps, Other };
  struct Message {
    std::uint8_t cls = 0;
    std::uint8_t id = 0;
    Content content = Content::Other;
    std::optional<core::GpsTime> time;  ///< RAWX epoch or NAV-TIMEGPS time
    int new_ephemerides = 0;            ///< ephemerides completed by this message
  };

  explicit UbxDecoder(UbxDecoderOptions options = {});

  /// Decodes one packet (class, id, payload). Error naming the message and what is wrong.
  Result<Message> decode(std::uint8_t cls, std::uint8_t id, std::span<const std::uint8_t> payload);
  /// RAWX epochs decoded so far, oldest first.
  std::optional<core::ObsEpoch> pop_epoch();

  [[nodiscard]] const core::NavigationData& navigation() const { return nav_; }
  [[nodiscard]] const std::optional<ubx::NavPvt>& nav_pvt() const { return pvt_; }
  [[nodiscard]] const std::optional<ubx::NavTimeGps>& nav_timegps() const { return timegps_; }
  [[nodiscard]] std::vector<std::pair<int, int>> glonass_channels() const;
  [[nodiscard]] const std::map<std::pair<int, int>, std::uint64_t>& message_counts() const { return counts_; }
  /// Recovered problems, each once ("G05: LNAV subframe without preamble").
  [[nodiscard]] const std::vector<std::string>& warnings() const { return warnings_; }
  /// Navigation words rejected (bad parity / CRC / Hamming, inconsistent).
  [[nodiscard]] std::uint64_t rejected_words() const { return rejected_words_; }

 private:
  struct SignalState {
    int lock_time_ms = 0;
    bool half_subtracted = false;
    bool pending_slip = false;
    bool seen = false;
  };
  Status add_rawx(const ubx::Rawx& rawx, Message& out);
  Status add_sfrbx(const ubx::Sfrbx& sfrbx, Message& out);
  void warn_once(const std::string& text);

  UbxDecoderOptions options_;
  std::optional<core::GpsTime> time_;
  std::vector<core::ObsEpoch> ready_;
  std::size_t ready_head_ = 0;
  std::map<std::tuple<int, char, char>, SignalState> signals_;
  std::map<int, int> glonass_channel_;
  navmsg::LnavAssembler lnav_;
  navmsg::GlonassAssembler glonass_;
  navmsg::GalileoInavAssembler galileo_;
  navmsg::BeidouD1Assembler beidou_;
  core::NavigationData nav_;
  std::optional<ubx::NavPvt> pvt_;
  std::optional<ubx::NavTimeGps> timegps_;
  std::map<std::pair<int, int>, std::uint64_t> counts_;
  std::vector<std::string> warnings_;
  std::set<std::string> warned_;
  std::uint64_t rejected_words_ = 0;
};

}  // namespace canyon::io
