#pragma once
// Broadcast navigation messages as the satellites send them, decoded into core ephemerides: GPS and QZSS LNAV
// subframes 1-3, GLONASS strings 1-4, Galileo I/NAV words 1-5, BeiDou D1 subframes 1-3 (MEO/IGSO satellites; the
// GEO D2 pages are not decoded). A receiver (u-blox RXM-SFRBX) hands over the words; each assembler keeps the
// latest words per satellite and returns an ephemeris once a consistent set is complete (same issue of data, same
// frame), and not again until the set changes.
//
// Layouts and scale factors: IS-GPS-200 20.3.3.3-4, IS-QZSS-PNT 5.3.2 (as GPS), GLONASS ICD 5.1 4.4-4.5 (strings,
// Hamming code 4.7), Galileo OS SIS ICD 4.3.5 (I/NAV pages, CRC-24Q) and table 40ff., BeiDou ICD B1I 5.2.4 (D1).
// Weeks are truncated in the messages; `reference` (the receiver's GPST time) resolves them. GLONASS times of day
// are Moscow time, converted with the leap seconds.

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <span>

#include "canyon/core/ephemeris.hpp"
#include "canyon/core/result.hpp"
#include "canyon/core/satellite.hpp"
#include "canyon/core/time.hpp"

namespace canyon::io::navmsg {

/// GPS/QZSS LNAV. A subframe is 10 words of 24 data bits (parity removed), 240 bits, most significant first.
class LnavAssembler {
 public:
  using Subframe = std::array<std::uint8_t, 30>;
  /// Adds a subframe of `sat`. An ephemeris when subframes 1, 2 and 3 agree (IODC & 0xFF == IODE, twice) and
  /// differ from the last one returned. Error for a subframe that cannot be valid (preamble, subframe id).
  Result<std::optional<core::KeplerEphemeris>> add(core::SatelliteId sat, const Subframe& subframe,
                                                   const core::GpsTime& reference);
  /// Klobuchar parameters of the last subframe 4 page 18 (GPS) seen, if any.
  [[nodiscard]] const std::optional<core::KlobucharParams>& klobuchar() const { return klobuchar_; }

 private:
  struct State {
    std::array<Subframe, 3> frames{};
    std::array<bool, 3> have{};
    int last_iode = -1;
    long long last_toe = -1;
  };
  std::map<core::SatelliteId, State> state_;
  std::optional<core::KlobucharParams> klobuchar_;
};

/// GLONASS strings: 85 bits (b85 .. b1, b85 the idle chip) in 11 bytes, most significant first.
class GlonassAssembler {
 public:
  using String = std::array<std::uint8_t, 11>;
  /// Whether the string's Hamming code (ICD 4.7) checks.
  [[nodiscard]] static bool hamming_ok(const String& s);
  /// Adds string 1-5 of a satellite (`channel`: its FDMA channel) received at `reference`. An ephemeris when strings
  /// 1-4 of one frame (received within 30 s) are there. Error for a string whose Hamming code fails.
  Result<std::optional<core::GlonassEphemeris>> add(int slot, int channel, const String& s,
                                                    const core::GpsTime& reference, const core::LeapSecondTable& leaps);

 private:
  struct State {
    std::array<String, 4> strings{};
    std::array<bool, 4> have{};
    std::array<core::GpsTime, 4> received{};  // strings 1-4 of one frame arrive within 30 s
    long long last_toe = -1;
  };
  std::map<int, State> state_;
};

/// Galileo I/NAV: a word is 128 bits (word type in the first 6 bits).
class GalileoInavAssembler {
 public:
  using Word = std::array<std::uint8_t, 16>;
  /// The word of an E1-B nominal page pair (even part, odd part: 120 bits each, as 2 x 4 32-bit words from a
  /// receiver). nullopt for an alert page; Error if the page pair's CRC fails or parts are out of order.
  static Result<std::optional<Word>> word_from_pages(std::span<const std::uint32_t, 8> page_words);
  /// Adds a word; an ephemeris when words 1-5 hold one IODnav.
  Result<std::optional<core::KeplerEphemeris>> add(int svid, const Word& word, const core::GpsTime& reference);

 private:
  struct State {
    std::array<Word, 5> words{};
    std::array<bool, 5> have{};
    int last_iod = -1;
    long long last_toe = -1;
  };
  std::map<int, State> state_;
};

/// BeiDou D1 (MEO/IGSO): a subframe is 10 words of 30 bits (word 1: 26 data + 4 parity bits; words 2-10: 22 data
/// bits then 8 parity bits), 300 bits, most significant first.
class BeidouD1Assembler {
 public:
  using Subframe = std::array<std::uint8_t, 38>;
  /// Adds a subframe of a satellite; an ephemeris when subframes 1-3 of one frame (SOW 0, +6, +12 s) are there.
  Result<std::optional<core::KeplerEphemeris>> add(int prn, const Subframe& subframe, const core::GpsTime& reference);
  /// Whether a BeiDou PRN is a GEO satellite (D2 navigation message).
  [[nodiscard]] static bool is_geo(int prn) { return prn <= 5 || prn >= 59; }

 private:
  struct State {
    std::array<std::array<std::uint8_t, 28>, 3> data{};  // 224 data bits per subframe
    std::array<double, 3> sow{};
    std::array<bool, 3> have{};
    long long last_toe = -1;
    int last_iode = -1;
  };
  std::map<int, State> state_;
};

}  // namespace canyon::io::navmsg
