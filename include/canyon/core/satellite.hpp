#pragma once
// Satellite identities, RINEX 3 signal codes, carrier frequencies and wavelengths.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace canyon::core {

enum class Constellation : std::uint8_t { Gps, Glonass, Galileo, BeiDou, Qzss };
inline constexpr int kNumConstellations = 5;

/// RINEX system letter: G R E C J.
[[nodiscard]] char system_letter(Constellation c);
[[nodiscard]] std::optional<Constellation> constellation_from_letter(char letter);
/// "GPS", "GLONASS", "Galileo", "BeiDou", "QZSS".
[[nodiscard]] std::string_view constellation_name(Constellation c);
/// Highest PRN/slot canyon accepts for a system (RINEX numbering: QZSS J01 = PRN 193).
[[nodiscard]] int max_prn(Constellation c);

/// One satellite: system and RINEX number (GPS PRN, GLONASS slot, Galileo SVID, BeiDou PRN, QZSS PRN - 192).
struct SatelliteId {
  Constellation system = Constellation::Gps;
  std::uint8_t prn = 0;

  [[nodiscard]] bool valid() const { return prn >= 1 && prn <= max_prn(system); }
  /// "G05", "R24", "J02".
  [[nodiscard]] std::string to_string() const;
  /// Dense index 0..kMaxSatellites-1 for arrays keyed by satellite.
  [[nodiscard]] int index() const;

  friend bool operator==(const SatelliteId& a, const SatelliteId& b) = default;
  // NOLINTNEXTLINE(modernize-use-nullptr): clang-tidy 14 misreads a defaulted operator<=>
  friend auto operator<=>(const SatelliteId& a, const SatelliteId& b) = default;
};
inline constexpr int kMaxSatellites = 32 + 27 + 36 + 63 + 10;

/// Parses "G05", "G 5", "E11"; a bare number (RINEX 2 "blank means GPS") is GPS. Returns nullopt if malformed.
[[nodiscard]] std::optional<SatelliteId> parse_satellite(std::string_view text);
/// Inverse of SatelliteId::index().
[[nodiscard]] SatelliteId satellite_from_index(int index);

/// A RINEX 3 signal: band digit ('1', '2', '5', '6', '7', '8', '4') and attribute letter ('C', 'W', 'X', ...),
/// as in observation codes "C1C", "L2W". Observation kind (C/L/D/S) is not part of the signal.
struct SignalCode {
  char band = '1';
  char attribute = 'C';

  /// "1C".
  [[nodiscard]] std::string to_string() const { return std::string{band, attribute}; }
  friend bool operator==(const SignalCode& a, const SignalCode& b) = default;
  // NOLINTNEXTLINE(modernize-use-nullptr): clang-tidy 14 misreads a defaulted operator<=>
  friend auto operator<=>(const SignalCode& a, const SignalCode& b) = default;
};

/// Parses "1C" (two characters). nullopt if the band is not a digit or the attribute not a letter.
[[nodiscard]] std::optional<SignalCode> parse_signal(std::string_view text);

/// GLONASS FDMA frequency channel number k in [-7, 6]; needed for GLONASS G1/G2 frequencies.
inline constexpr int kNoGlonassChannel = 99;

/// Carrier frequency (Hz) of a signal of a system; nullopt if the band does not exist for that system, or if it is
/// a GLONASS FDMA band and `glonass_channel` is kNoGlonassChannel.
[[nodiscard]] std::optional<double> carrier_frequency_hz(Constellation system, SignalCode signal,
                                                         int glonass_channel = kNoGlonassChannel);
/// Wavelength (m) = c / carrier_frequency_hz.
[[nodiscard]] std::optional<double> wavelength_m(Constellation system, SignalCode signal,
                                                 int glonass_channel = kNoGlonassChannel);

/// Frequency rank of a band within its system, the order in which canyon pairs frequencies (as RTKLIB does):
///   GPS/QZSS: L1 0, L2 1, L5 2 (QZSS L6 3); GLONASS: G1/G1a 0, G2/G2a 1, G3 2;
///   Galileo: E1 0, E5b 1, E5a 2, E6 3, E5 4; BeiDou: B1I 0, B2I/B2b 1, B3I 2, B1C 3, B2a 4, B2 5.
/// nullopt for a band the system does not have.
[[nodiscard]] std::optional<int> frequency_rank(Constellation system, char band);

/// Tracking-code preference on a system's band, best first (e.g. GPS L1: "CPWYMSLXN"): the one table by which the
/// single point (gnss/spp.hpp) and the RTK filter's observables (rtk/observables.hpp) choose among the signals a
/// receiver tracks on one band of one satellite, so that both use the same signal. "" for a band the system does not
/// have.
[[nodiscard]] const char* code_priority(Constellation system, char band);

}  // namespace canyon::core

namespace canyon::core {

/// Which constellations a processing step uses. Options structs inherit it, so that `use_gps` etc. read as their own
/// fields and the logic exists once.
struct ConstellationFlags {
  bool use_gps = true;
  bool use_glonass = true;
  bool use_galileo = true;
  bool use_beidou = true;
  bool use_qzss = true;

  [[nodiscard]] bool uses(Constellation c) const;
  [[nodiscard]] bool any() const { return use_gps || use_glonass || use_galileo || use_beidou || use_qzss; }
  /// Letters of the constellations used, in G R E C J order.
  [[nodiscard]] std::vector<std::string> letters() const;
  /// Sets the flags from letters; false (flags unchanged) if a letter is not one of G R E C J.
  [[nodiscard]] bool set_from_letters(const std::vector<std::string>& letters, std::string* bad_letter = nullptr);
};

}  // namespace canyon::core
