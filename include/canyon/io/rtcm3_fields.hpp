#pragma once
// RTCM 3 message layouts, each written once for both directions (RTCM 10403.3 section 3.5).
//
// A layout is a function template that names a message's data fields in transmission order, one call per field:
//     io(s(79, 14, p2(-43), "IDOT", Unit::Semicircle), e.idot_radps);  // DF079 IDOT
// a Field (data field number DFxxx, width, encoding, resolution, unit, name) and the value it carries. It runs with
// a FieldWriter (encoding), a FieldReader (decoding) or a FieldCounter (the message length in bits), so that the
// encoder and the decoder cannot disagree on a width, a scale factor or the order of two fields. MSM satellite and
// signal data send one field for every satellite (cell) in turn: io.each(field, items, &Item::member).
//
// Values:
//  - A floating-point value is physical: the field's raw value times `lsb` is the value in the message's unit,
//    converted to the value's (semicircles -> rad, km -> m, negated). The writer rounds to the nearest raw value;
//    one that does not fit is written as 0 and makes the message an Error naming the field.
//  - An integral or bool value is the raw value. It is range-checked the same way when the field has a name, else
//    written masked (its low bits): the encoder reduced it already (a week modulo 1024) or the message's rule is
//    to (DF003 in an MSM). Its `lsb`, if any, documents the field and serves the code that converts it.
//  - A std::string is a counter of `bits` bits (DF029, ...) followed by that many characters (the next DF).
//  - A field without a value is one canyon does not keep: written as `fixed` (0 unless given), skipped when read.
// What a message carries in a form canyon's structures do not (message number, truncated week, accuracy index,
// health bits) sits in a small wire struct next to its layout; the encoders and decoders in rtcm3_*.cpp fill it.

#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>

#include "canyon/core/result.hpp"
#include "canyon/io/bits.hpp"
#include "canyon/io/rtcm3.hpp"

namespace canyon::io::rtcm3::fields {

/// RTCM data types: uint(n) and bit(n); int(n), two's complement; intS(n), sign-magnitude.
enum class Encoding : std::uint8_t { Unsigned, TwosComplement, SignMagnitude };
/// The unit of a value when it differs from the message's: radians for semicircles (with the ICD's pi, kGpsPi),
/// metres for kilometres, or the opposite sign.
enum class Unit : std::uint8_t { Same, Semicircle, Kilometre, Negated };

/// One data field.
struct Field {
  int df = 0;  ///< RTCM 10403.3 data field number (DF001: reserved)
  unsigned bits = 0;
  Encoding encoding = Encoding::Unsigned;
  double lsb = 1.0;  ///< resolution: message value = raw * lsb
  Unit unit = Unit::Same;
  const char* name = nullptr;  ///< named in the encoder's range error; nullptr: integral values written masked
  std::uint64_t fixed = 0;     ///< fields without a value: what the encoder writes
};

/// 2^e, exactly.
constexpr double p2(int e) {
  double v = 1.0;
  for (; e > 0; --e) v *= 2.0;
  for (; e < 0; ++e) v *= 0.5;
  return v;
}

/// uint(n), raw.
constexpr Field u(int df, unsigned bits, const char* name = nullptr) {
  return {df, bits, Encoding::Unsigned, 1.0, Unit::Same, name};
}
/// uint(n) of resolution `lsb`.
constexpr Field u(int df, unsigned bits, double lsb, const char* name = nullptr, Unit unit = Unit::Same) {
  return {df, bits, Encoding::Unsigned, lsb, unit, name};
}
/// int(n), two's complement.
constexpr Field s(int df, unsigned bits, double lsb = 1.0, const char* name = nullptr, Unit unit = Unit::Same) {
  return {df, bits, Encoding::TwosComplement, lsb, unit, name};
}
/// intS(n), sign-magnitude (GLONASS).
constexpr Field sm(int df, unsigned bits, double lsb, const char* name = nullptr, Unit unit = Unit::Same) {
  return {df, bits, Encoding::SignMagnitude, lsb, unit, name};
}
/// Text: DF`df` counter uint8 (at most 31), then DF`df + 1` that many char8 characters.
constexpr Field text(int df, const char* name) {
  return {df, 8, Encoding::Unsigned, 1.0, Unit::Same, name};
}
/// A field canyon does not keep: written as `value`, skipped when decoding.
constexpr Field unused(int df, unsigned bits, std::uint64_t value = 0) {
  return {df, bits, Encoding::Unsigned, 1.0, Unit::Same, nullptr, value};
}
/// DF001, reserved bits.
constexpr Field reserved(unsigned bits) {
  return unused(1, bits);
}

/// Value in the message's unit from a value in `unit`, and back.
constexpr double to_message_unit(double value, Unit unit) {
  switch (unit) {
    case Unit::Same: return value;
    case Unit::Semicircle: return value / kGpsPi;
    case Unit::Kilometre: return value * 1e-3;
    case Unit::Negated: return -value;
  }
  return value;
}
constexpr double from_message_unit(double value, Unit unit) {
  switch (unit) {
    case Unit::Same: return value;
    case Unit::Semicircle: return value * kGpsPi;
    case Unit::Kilometre: return value * 1e3;
    case Unit::Negated: return -value;
  }
  return value;
}

/// Decodes: each field read into its value. Unchecked (kChecked false), the caller has checked that the payload
/// holds every field (FieldCounter); checked, a field the payload does not hold is not read and clears ok() (for
/// messages of variable length: 1007/1008/1033, 1230). Text is always checked.
template <bool kChecked = false>
class FieldReader {
 public:
  explicit FieldReader(std::span<const std::uint8_t> payload) : r_(payload) {}

  [[nodiscard]] bool ok() const { return ok_; }
  [[nodiscard]] std::size_t position() const { return r_.position(); }
  [[nodiscard]] std::size_t bits_left() const { return r_.bits_left(); }

  template <class T>
  void operator()(const Field& f, T& value) {
    if (holds(f.bits)) store(f, r_.u(f.bits), value);
  }
  void operator()(const Field& f) {
    if (holds(f.bits)) r_.skip(f.bits);
  }
  void operator()(const Field& f, std::string& text) {
    if (!ok_ || r_.bits_left() < f.bits) {
      ok_ = false;
      return;
    }
    const auto n = static_cast<std::size_t>(r_.u(f.bits));
    if (r_.bits_left() < 8 * n) {
      ok_ = false;
      return;
    }
    text.clear();
    for (std::size_t i = 0; i < n; ++i) text.push_back(static_cast<char>(r_.u(8)));
  }
  /// The field of each item in turn (MSM satellite and signal data).
  template <class Item, class Member>
  void each(const Field& f, std::span<Item> items, Member Item::*member) {
    if constexpr (kChecked) {
      for (Item& item : items) (*this)(f, item.*member);
    } else {
      const Field field = f;  // local copies: the values stored cannot alias them, so they stay in registers
      BitReader r = r_;
      for (Item& item : items) store(field, r.u(field.bits), item.*member);
      r_ = r;
    }
  }

 private:
  bool holds(std::size_t bits) {
    if constexpr (kChecked) {
      if (!ok_ || r_.bits_left() < bits) {
        ok_ = false;
        return false;
      }
    }
    return true;
  }
  /// Stores the raw value of a field into its value.
  template <class T>
  static void store(const Field& f, std::uint64_t raw, T& value) {
    if constexpr (std::is_floating_point_v<T>) {
      const double v =
          f.encoding == Encoding::Unsigned ? static_cast<double>(raw) : static_cast<double>(signed_value(raw, f));
      value = from_message_unit(v * f.lsb, f.unit);
    } else if constexpr (std::is_same_v<T, bool>) {
      value = raw != 0;
    } else if constexpr (std::is_signed_v<T>) {
      value = static_cast<T>(f.encoding == Encoding::Unsigned ? static_cast<std::int64_t>(raw) : signed_value(raw, f));
    } else {
      value = static_cast<T>(raw);  // unsigned values hold unsigned fields
    }
  }
  static std::int64_t signed_value(std::uint64_t raw, const Field& f) {
    return f.encoding == Encoding::SignMagnitude ? sign_magnitude_value(raw, f.bits)
                                                 : twos_complement_value(raw, f.bits);
  }

  BitReader r_;
  bool ok_ = true;
};

/// Encodes: each value written into its field through `Bits` (BitWriter or FixedBitWriter). status() names the
/// first value that did not fit; the message is then complete but for it (written as 0). The writer keeps no
/// string of its own until status() (so that it stays in registers when a layout is inlined).
template <class Bits>
class FieldWriter {
 public:
  static constexpr std::size_t kMaxText = 31;  // DF029, DF032, DF227, DF229, DF231

  FieldWriter(Bits& bits, int number) : bits_(bits), number_(number) {}

  template <class T>
  void operator()(const Field& f, const T& value) {
    bits_.u(bits_of(f, value), f.bits);
  }
  void operator()(const Field& f) { bits_.u(f.fixed, f.bits); }
  void operator()(const Field& f, const std::string& text) {
    if (text.size() > kMaxText) {
      if (failed_ == nullptr) {
        failed_ = f.name;
        long_text_ = &text;
      }
      return;
    }
    bits_.u(text.size(), f.bits);
    for (const char c : text) bits_.u(static_cast<unsigned char>(c), 8);
  }
  /// The field of each item in turn (MSM satellite and signal data).
  template <class Item, class Member>
  void each(const Field& f, std::span<Item> items, Member std::remove_const_t<Item>::*member) {
    const Field field = f;  // local copies: the bytes written cannot alias them, so they stay in registers
    if constexpr (std::is_copy_constructible_v<Bits>) {
      Bits bits = bits_;
      for (const Item& item : items) bits.u(bits_of(field, item.*member), field.bits);
      bits_ = bits;
    } else {
      for (const Item& item : items) bits_.u(bits_of(field, item.*member), field.bits);
    }
  }

  [[nodiscard]] Status status() const {
    if (failed_ == nullptr) return Ok{};
    const std::string message = "RTCM 3 message " + std::to_string(number_) + ": " +
                                (failed_[0] != '\0' ? std::string(failed_) : "DF" + std::to_string(failed_df_));
    if (long_text_ != nullptr) return Error{message + " '" + *long_text_ + "' longer than 31 characters"};
    return Error{message + " out of its field's range"};
  }

 private:
  /// The bits of a value in its field; one that does not fit is recorded for status() and written as 0.
  template <class T>
  std::uint64_t bits_of(const Field& f, const T& value) {
    std::int64_t v = 0;
    if constexpr (std::is_floating_point_v<T>) {
      const double q = std::round(to_message_unit(value, f.unit) / f.lsb);
      if (!fits(q, f)) return fail(f);
      v = static_cast<std::int64_t>(q);
    } else {
      v = static_cast<std::int64_t>(value);
      if (f.name != nullptr && !fits(static_cast<double>(v), f)) [[unlikely]] {
        return fail(f);
      }
    }
    return f.encoding == Encoding::SignMagnitude ? sign_magnitude_bits(v, f.bits) : static_cast<std::uint64_t>(v);
  }
  /// Whether a raw value (whole number or NaN) fits the field.
  static bool fits(double q, const Field& f) {
    const double half = std::ldexp(1.0, static_cast<int>(f.bits) - 1);
    switch (f.encoding) {
      case Encoding::Unsigned: return q >= 0.0 && q < 2.0 * half;
      case Encoding::TwosComplement: return q >= -half && q < half;
      case Encoding::SignMagnitude: return q > -half && q < half;
    }
    return false;
  }
  std::uint64_t fail(const Field& f) {
    if (failed_ == nullptr) {
      failed_ = f.name != nullptr ? f.name : "";
      failed_df_ = f.df;
    }
    return 0;
  }

  Bits& bits_;
  int number_;
  const char* failed_ = nullptr;  // name of the first field that did not fit ("": unnamed)
  int failed_df_ = 0;
  const std::string* long_text_ = nullptr;  // its text, if too long
};

/// Counts the bits of a layout.
class FieldCounter {
 public:
  template <class T>
  constexpr void operator()(const Field& f, const T& /*value*/) {
    bits_ += f.bits;
  }
  constexpr void operator()(const Field& f) { bits_ += f.bits; }
  void operator()(const Field& f, const std::string& text) { bits_ += f.bits + 8 * text.size(); }
  template <class Item, class Member>
  constexpr void each(const Field& f, std::span<Item> items, Member std::remove_const_t<Item>::* /*member*/) {
    bits_ += f.bits * items.size();
  }
  [[nodiscard]] constexpr std::size_t bits() const { return bits_; }

 private:
  std::size_t bits_ = 0;
};

// ---------------------------------------------------------------------------------------------------------------
// Multiple Signal Messages (RTCM 10403.3 section 3.5.12): header, satellite data, signal data. Satellite and signal
// data are sent field by field: one field for every satellite (or cell) in turn, then the next field.

/// Message number and masks (DF394-DF396).
struct MsmMasks {
  int number = 0;
  std::uint64_t satellites = 0;  ///< DF394, satellite id 1 in the most significant bit
  std::uint32_t signals = 0;     ///< DF395, signal id 1 in the most significant bit
  std::uint64_t cells = 0;       ///< DF396, nsat x nsig bits
};

/// The header, DF002 to DF395 (169 bits).
template <class Io, class Header, class Masks>
constexpr void msm_header_fields(Io& io, Header& h, Masks& masks) {
  io(u(2, 12), masks.number);                  // DF002 message number
  io(u(3, 12), h.station_id);                  // DF003 reference station id
  io(u(4, 30), h.epoch_time);                  // DF004 / DF248 / DF427 / DF428 epoch time; DF416 + DF034 GLONASS
  io(u(393, 1), h.multiple_message);           // DF393 multiple message bit
  io(u(409, 3), h.iods);                       // DF409 issue of data station
  io(reserved(7));                             // DF001 reserved
  io(u(411, 2), h.clock_steering);             // DF411 clock steering indicator
  io(u(412, 2), h.external_clock);             // DF412 external clock indicator
  io(u(417, 1), h.divergence_free_smoothing);  // DF417 divergence-free smoothing indicator
  io(u(418, 3), h.smoothing_interval);         // DF418 smoothing interval
  io(u(394, 64), masks.satellites);            // DF394 satellite mask
  io(u(395, 32), masks.signals);               // DF395 signal mask
}

/// DF396 cell mask, after the header: one bit per satellite x signal of the masks.
template <class Io, class Masks>
constexpr void msm_cell_mask_field(Io& io, Masks& masks) {
  const int cells = std::popcount(masks.satellites) * std::popcount(masks.signals);
  io(u(396, static_cast<unsigned>(cells)), masks.cells);
}

/// Satellite data as sent (raw field values), one per satellite.
struct MsmSatelliteData {
  std::uint32_t rough_range_ms;    ///< DF397 (255: invalid)
  std::uint32_t info;              ///< DF419
  std::uint32_t rough_range_frac;  ///< DF398
  std::int32_t rough_rate;         ///< DF399 (-8192: invalid)
};
/// Signal data as sent (raw field values), one per cell.
struct MsmSignalData {
  std::int32_t pseudorange;  ///< DF400 / DF405 (most negative: invalid)
  std::int32_t phase_range;  ///< DF401 / DF406 (most negative: invalid)
  std::uint32_t lock_time;   ///< DF402 / DF407
  bool half_cycle;           ///< DF420
  std::uint32_t cnr;         ///< DF403 / DF408 (0: not given)
  std::int32_t fine_rate;    ///< DF404 (-16384: invalid)
};

/// The satellite and signal data fields of an MSM type.
struct MsmFields {
  bool extended = false;         ///< MSM5, MSM7: extended satellite information and phase range rates
  bool high_resolution = false;  ///< MSM6, MSM7
  Field rough_range_ms;          ///< satellite data
  Field info;                    ///< extended only
  Field rough_range_frac;
  Field rough_rate;   ///< extended only
  Field pseudorange;  ///< signal data
  Field phase_range;
  Field lock_time;
  Field half_cycle;
  Field cnr;
  Field fine_rate;                 ///< extended only
  std::size_t satellite_bits = 0;  ///< per satellite
  std::size_t cell_bits = 0;       ///< per cell
};

/// The fields of MSM type 4-7 (sizes: see kMsmFields).
constexpr MsmFields make_msm_fields(int type) {
  const bool high = type >= 6;
  MsmFields f;
  f.extended = type == 5 || type == 7;
  f.high_resolution = high;
  f.rough_range_ms = u(397, 8);                                      // DF397 rough range, whole ms
  f.info = u(419, 4);                                                // DF419 extended satellite info
  f.rough_range_frac = u(398, 10, p2(-10));                          // DF398 rough range modulo 1 ms
  f.rough_rate = s(399, 14, 1.0);                                    // DF399 rough phase range rate, m/s
  f.pseudorange = high ? s(405, 20, p2(-29)) : s(400, 15, p2(-24));  // DF405 / DF400 fine pseudorange, ms
  f.phase_range = high ? s(406, 24, p2(-31)) : s(401, 22, p2(-29));  // DF406 / DF401 fine phase range, ms
  f.lock_time = high ? u(407, 10) : u(402, 4);                       // DF407 / DF402 lock time indicator
  f.half_cycle = u(420, 1);                                          // DF420 half-cycle ambiguity indicator
  f.cnr = high ? u(408, 10, p2(-4)) : u(403, 6, 1.0);                // DF408 / DF403 CNR, dB-Hz
  f.fine_rate = s(404, 15, 1e-4);                                    // DF404 fine phase range rate, m/s
  return f;
}

/// Satellite data of `sats` (in satellite id order), then signal data of `cells` (satellite-major); each field for
/// every satellite (cell) in turn, then the next field.
template <class Io, class Sat, class Cell>
constexpr void msm_data_fields(Io& io, const MsmFields& f, std::span<Sat> sats, std::span<Cell> cells) {
  using SatData = std::remove_const_t<Sat>;
  using CellData = std::remove_const_t<Cell>;
  io.each(f.rough_range_ms, sats, &SatData::rough_range_ms);          // DF397
  if (f.extended) io.each(f.info, sats, &SatData::info);              // DF419
  io.each(f.rough_range_frac, sats, &SatData::rough_range_frac);      // DF398
  if (f.extended) io.each(f.rough_rate, sats, &SatData::rough_rate);  // DF399
  io.each(f.pseudorange, cells, &CellData::pseudorange);              // DF400 / DF405
  io.each(f.phase_range, cells, &CellData::phase_range);              // DF401 / DF406
  io.each(f.lock_time, cells, &CellData::lock_time);                  // DF402 / DF407
  io.each(f.half_cycle, cells, &CellData::half_cycle);                // DF420
  io.each(f.cnr, cells, &CellData::cnr);                              // DF403 / DF408
  if (f.extended) io.each(f.fine_rate, cells, &CellData::fine_rate);  // DF404
}

/// make_msm_fields with the bits per satellite and per cell that msm_data_fields sends.
constexpr MsmFields sized_msm_fields(int type) {
  MsmFields f = make_msm_fields(type);
  std::array<MsmSatelliteData, 1> sat{};
  std::array<MsmSignalData, 1> cell{};
  FieldCounter one_sat;
  msm_data_fields(one_sat, f, std::span<MsmSatelliteData>(sat), std::span<MsmSignalData>{});
  FieldCounter one_cell;
  msm_data_fields(one_cell, f, std::span<MsmSatelliteData>{}, std::span<MsmSignalData>(cell));
  f.satellite_bits = one_sat.bits();
  f.cell_bits = one_cell.bits();
  return f;
}

inline constexpr std::array<MsmFields, 4> kMsmFields = {sized_msm_fields(4), sized_msm_fields(5), sized_msm_fields(6),
                                                        sized_msm_fields(7)};
/// MSM type 4-7.
constexpr const MsmFields& msm_fields(int type) {
  return kMsmFields[static_cast<std::size_t>(type - 4)];
}

/// Bits of the MSM header (DF002-DF395): 169.
constexpr std::size_t msm_header_bits() {
  FieldCounter counter;
  MsmHeader header;
  MsmMasks masks;
  msm_header_fields(counter, header, masks);
  return counter.bits();
}

// ---------------------------------------------------------------------------------------------------------------
// Station messages.

inline constexpr double kArpLsbM = 1e-4;            // DF025-DF027
inline constexpr double kAntennaHeightLsbM = 1e-4;  // DF028
inline constexpr double kGlonassBiasLsbM = 0.02;    // DF423-DF426

/// 1005/1006 values that StationPosition holds otherwise.
struct StationWire {
  int number = 1005;
  double antenna_height_m = 0.0;  ///< 1006
};

/// 1005 stationary antenna reference point, 1006 with the antenna height.
template <class Io, class Station, class Wire>
constexpr void station_position_fields(Io& io, Station& st, Wire& w) {
  io(u(2, 12), w.number);                         // DF002 message number
  io(u(3, 12), st.station_id);                    // DF003 reference station id
  io(u(21, 6), st.itrf_year);                     // DF021 ITRF realization year
  io(u(22, 1), st.gps);                           // DF022 GPS indicator
  io(u(23, 1), st.glonass);                       // DF023 GLONASS indicator
  io(u(24, 1), st.galileo);                       // DF024 Galileo indicator
  io(u(141, 1), st.reference_station);            // DF141 reference-station indicator
  io(s(25, 38, kArpLsbM, "ARP"), st.arp_E_m[0]);  // DF025 antenna reference point ECEF-X, m
  io(u(142, 1), st.single_oscillator);            // DF142 single receiver oscillator indicator
  io(reserved(1));                                // DF001 reserved
  io(s(26, 38, kArpLsbM, "ARP"), st.arp_E_m[1]);  // DF026 ECEF-Y, m
  io(u(364, 2), st.quarter_cycle);                // DF364 quarter cycle indicator
  io(s(27, 38, kArpLsbM, "ARP"), st.arp_E_m[2]);  // DF027 ECEF-Z, m
  if (w.number == 1006) {
    io(u(28, 16, kAntennaHeightLsbM, "antenna height"), w.antenna_height_m);  // DF028 antenna height, m
  }
}

/// 1033 receiver and antenna descriptors; 1007 (antenna descriptor) and 1008 (and serial number) are its first fields.
template <class Io, class Info>
constexpr void antenna_info_fields(Io& io, Info& a, int& number) {
  io(u(2, 12), number);                                      // DF002 message number
  io(u(3, 12), a.station_id);                                // DF003 reference station id
  io(text(29, "antenna descriptor"), a.antenna_descriptor);  // DF029 counter, DF030 antenna descriptor
  io(u(31, 8), a.antenna_setup_id);                          // DF031 antenna setup id
  if (number == 1007) return;
  io(text(32, "antenna serial number"), a.antenna_serial);  // DF032 counter, DF033 antenna serial number
  if (number == 1008) return;
  io(text(227, "receiver type"), a.receiver_type);             // DF227 counter, DF228 receiver type descriptor
  io(text(229, "receiver firmware"), a.receiver_firmware);     // DF229 counter, DF230 firmware version
  io(text(231, "receiver serial number"), a.receiver_serial);  // DF231 counter, DF232 receiver serial number
}

/// 1230 values that GlonassBiases holds otherwise.
struct GlonassBiasWire {
  int number = 1230;
  unsigned mask = 0;                  ///< DF422: L1 C/A, L1 P, L2 C/A, L2 P from the most significant bit
  std::array<double, 4> bias_m = {};  ///< in mask order, present where the mask bit is set
};

/// 1230 GLONASS L1 and L2 code-phase biases.
template <class Io, class Biases, class Wire>
constexpr void glonass_bias_fields(Io& io, Biases& b, Wire& w) {
  io(u(2, 12), w.number);      // DF002 message number
  io(u(3, 12), b.station_id);  // DF003 reference station id
  io(u(421, 1), b.aligned);    // DF421 GLONASS code-phase bias indicator
  io(reserved(3));             // DF001 reserved
  io(u(422, 4), w.mask);       // DF422 GLONASS FDMA signals mask
  for (std::size_t i = 0; i < 4; ++i) {
    // DF423 L1 C/A, DF424 L1 P, DF425 L2 C/A, DF426 L2 P code-phase bias, m
    if ((w.mask & (8U >> i)) != 0) io(s(423 + static_cast<int>(i), 16, kGlonassBiasLsbM, "bias"), w.bias_m[i]);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Ephemerides. Angles are in semicircles (Unit::Semicircle converts with kGpsPi).

/// Kepler ephemeris values that KeplerEphemeris holds otherwise (or not at all).
struct KeplerWire {
  int number = 0;        ///< DF002: 1019, 1042, 1044, 1045, 1046
  int prn = 0;           ///< satellite id
  int week = 0;          ///< week as sent: modulo 1024 (GPS, QZSS), 8192 (BeiDou), 4096 (Galileo)
  int accuracy = 0;      ///< URA index (GPS, QZSS, BeiDou), SISA index (Galileo)
  int l2_codes = 0;      ///< GPS DF078, QZSS DF451: KeplerEphemeris::data_source & 3
  double toc_s = 0.0;    ///< clock reference time, seconds of the system's week
  int fit_interval = 0;  ///< GPS DF137, QZSS DF457: 1 = longer than 4 hours
  int health = 0;        ///< BeiDou DF515 SatH1
  int e5a_health = 0;    ///< Galileo DF314 E5a signal health status
  int e5a_validity = 0;  ///< DF315 E5a data validity status
  int e5b_health = 0;    ///< DF316
  int e5b_validity = 0;  ///< DF317
  int e1b_health = 0;    ///< DF287
  int e1b_validity = 0;  ///< DF288
};

/// 1019 GPS ephemeris, 488 bits.
template <class Io, class Eph, class Wire>
constexpr void gps_ephemeris_fields(Io& io, Eph& e, Wire& w) {
  constexpr Unit kSc = Unit::Semicircle;
  io(u(2, 12), w.number);                                       // DF002 message number
  io(u(9, 6, "satellite id"), w.prn);                           // DF009 satellite id
  io(u(76, 10), w.week);                                        // DF076 week number
  io(u(77, 4, "URA"), w.accuracy);                              // DF077 SV accuracy (URA index)
  io(u(78, 2), w.l2_codes);                                     // DF078 code on L2
  io(s(79, 14, p2(-43), "IDOT", kSc), e.idot_radps);            // DF079 IDOT
  io(u(71, 8, "IODE"), e.iode);                                 // DF071 IODE
  io(u(81, 16, 16.0, "toc"), w.toc_s);                          // DF081 toc, s
  io(s(82, 8, p2(-55), "af2"), e.af2_sps2);                     // DF082 af2
  io(s(83, 16, p2(-43), "af1"), e.af1_sps);                     // DF083 af1
  io(s(84, 22, p2(-31), "af0"), e.af0_s);                       // DF084 af0
  io(u(85, 10, "IODC"), e.iodc);                                // DF085 IODC
  io(s(86, 16, p2(-5), "Crs"), e.crs_m);                        // DF086 Crs
  io(s(87, 16, p2(-43), "delta n", kSc), e.delta_n_radps);      // DF087 delta n
  io(s(88, 32, p2(-31), "M0", kSc), e.m0_rad);                  // DF088 M0
  io(s(89, 16, p2(-29), "Cuc"), e.cuc_rad);                     // DF089 Cuc
  io(u(90, 32, p2(-33), "e"), e.e);                             // DF090 eccentricity
  io(s(91, 16, p2(-29), "Cus"), e.cus_rad);                     // DF091 Cus
  io(u(92, 32, p2(-19), "sqrt A"), e.sqrt_a_sqrtm);             // DF092 sqrt A
  io(u(93, 16, 16.0, "toe"), e.toe_sow_s);                      // DF093 toe, s
  io(s(94, 16, p2(-29), "Cic"), e.cic_rad);                     // DF094 Cic
  io(s(95, 32, p2(-31), "OMEGA0", kSc), e.omega0_rad);          // DF095 OMEGA0
  io(s(96, 16, p2(-29), "Cis"), e.cis_rad);                     // DF096 Cis
  io(s(97, 32, p2(-31), "i0", kSc), e.i0_rad);                  // DF097 i0
  io(s(98, 16, p2(-5), "Crc"), e.crc_m);                        // DF098 Crc
  io(s(99, 32, p2(-31), "omega", kSc), e.omega_rad);            // DF099 omega
  io(s(100, 24, p2(-43), "OMEGADOT", kSc), e.omega_dot_radps);  // DF100 OMEGADOT
  io(s(101, 8, p2(-31), "TGD"), e.tgd_s[0]);                    // DF101 tGD
  io(u(102, 6, "health"), e.health);                            // DF102 SV health
  io(unused(103, 1));                                           // DF103 L2 P data flag
  io(u(137, 1), w.fit_interval);                                // DF137 fit interval
}

/// 1044 QZSS ephemeris, 485 bits.
template <class Io, class Eph, class Wire>
constexpr void qzss_ephemeris_fields(Io& io, Eph& e, Wire& w) {
  constexpr Unit kSc = Unit::Semicircle;
  io(u(2, 12), w.number);                                       // DF002 message number
  io(u(429, 4, "satellite id"), w.prn);                         // DF429 satellite id
  io(u(430, 16, 16.0, "toc"), w.toc_s);                         // DF430 toc, s
  io(s(431, 8, p2(-55), "af2"), e.af2_sps2);                    // DF431 af2
  io(s(432, 16, p2(-43), "af1"), e.af1_sps);                    // DF432 af1
  io(s(433, 22, p2(-31), "af0"), e.af0_s);                      // DF433 af0
  io(u(434, 8, "IODE"), e.iode);                                // DF434 IODE
  io(s(435, 16, p2(-5), "Crs"), e.crs_m);                       // DF435 Crs
  io(s(436, 16, p2(-43), "delta n", kSc), e.delta_n_radps);     // DF436 delta n
  io(s(437, 32, p2(-31), "M0", kSc), e.m0_rad);                 // DF437 M0
  io(s(438, 16, p2(-29), "Cuc"), e.cuc_rad);                    // DF438 Cuc
  io(u(439, 32, p2(-33), "e"), e.e);                            // DF439 eccentricity
  io(s(440, 16, p2(-29), "Cus"), e.cus_rad);                    // DF440 Cus
  io(u(441, 32, p2(-19), "sqrt A"), e.sqrt_a_sqrtm);            // DF441 sqrt A
  io(u(442, 16, 16.0, "toe"), e.toe_sow_s);                     // DF442 toe, s
  io(s(443, 16, p2(-29), "Cic"), e.cic_rad);                    // DF443 Cic
  io(s(444, 32, p2(-31), "OMEGA0", kSc), e.omega0_rad);         // DF444 OMEGA0
  io(s(445, 16, p2(-29), "Cis"), e.cis_rad);                    // DF445 Cis
  io(s(446, 32, p2(-31), "i0", kSc), e.i0_rad);                 // DF446 i0
  io(s(447, 16, p2(-5), "Crc"), e.crc_m);                       // DF447 Crc
  io(s(448, 32, p2(-31), "omega", kSc), e.omega_rad);           // DF448 omega
  io(s(449, 24, p2(-43), "OMEGADOT", kSc), e.omega_dot_radps);  // DF449 OMEGADOT
  io(s(450, 14, p2(-43), "IDOT", kSc), e.idot_radps);           // DF450 IDOT
  io(u(451, 2), w.l2_codes);                                    // DF451 codes on L2
  io(u(452, 10), w.week);                                       // DF452 week number
  io(u(453, 4, "URA"), w.accuracy);                             // DF453 URA index
  io(u(454, 6, "health"), e.health);                            // DF454 SV health
  io(s(455, 8, p2(-31), "TGD"), e.tgd_s[0]);                    // DF455 tGD
  io(u(456, 10, "IODC"), e.iodc);                               // DF456 IODC
  io(u(457, 1), w.fit_interval);                                // DF457 fit interval
}

/// 1042 BeiDou ephemeris, 511 bits. Times in BDT.
template <class Io, class Eph, class Wire>
constexpr void beidou_ephemeris_fields(Io& io, Eph& e, Wire& w) {
  constexpr Unit kSc = Unit::Semicircle;
  io(u(2, 12), w.number);                                       // DF002 message number
  io(u(488, 6, "satellite id"), w.prn);                         // DF488 satellite id
  io(u(489, 13), w.week);                                       // DF489 week number
  io(u(490, 4, "URAI"), w.accuracy);                            // DF490 URA index
  io(s(491, 14, p2(-43), "IDOT", kSc), e.idot_radps);           // DF491 IDOT
  io(u(492, 5, "AODE"), e.iode);                                // DF492 AODE
  io(u(493, 17, 8.0, "toc"), w.toc_s);                          // DF493 toc, s
  io(s(494, 11, p2(-66), "a2"), e.af2_sps2);                    // DF494 a2
  io(s(495, 22, p2(-50), "a1"), e.af1_sps);                     // DF495 a1
  io(s(496, 24, p2(-33), "a0"), e.af0_s);                       // DF496 a0
  io(u(497, 5, "AODC"), e.iodc);                                // DF497 AODC
  io(s(498, 18, p2(-6), "Crs"), e.crs_m);                       // DF498 Crs
  io(s(499, 16, p2(-43), "delta n", kSc), e.delta_n_radps);     // DF499 delta n
  io(s(500, 32, p2(-31), "M0", kSc), e.m0_rad);                 // DF500 M0
  io(s(501, 18, p2(-31), "Cuc"), e.cuc_rad);                    // DF501 Cuc
  io(u(502, 32, p2(-33), "e"), e.e);                            // DF502 eccentricity
  io(s(503, 18, p2(-31), "Cus"), e.cus_rad);                    // DF503 Cus
  io(u(504, 32, p2(-19), "sqrt A"), e.sqrt_a_sqrtm);            // DF504 sqrt A
  io(u(505, 17, 8.0, "toe"), e.toe_sow_s);                      // DF505 toe, s
  io(s(506, 18, p2(-31), "Cic"), e.cic_rad);                    // DF506 Cic
  io(s(507, 32, p2(-31), "OMEGA0", kSc), e.omega0_rad);         // DF507 OMEGA0
  io(s(508, 18, p2(-31), "Cis"), e.cis_rad);                    // DF508 Cis
  io(s(509, 32, p2(-31), "i0", kSc), e.i0_rad);                 // DF509 i0
  io(s(510, 18, p2(-6), "Crc"), e.crc_m);                       // DF510 Crc
  io(s(511, 32, p2(-31), "omega", kSc), e.omega_rad);           // DF511 omega
  io(s(512, 24, p2(-43), "OMEGADOT", kSc), e.omega_dot_radps);  // DF512 OMEGADOT
  io(s(513, 10, 1e-10, "TGD1"), e.tgd_s[0]);                    // DF513 TGD1, s
  io(s(514, 10, 1e-10, "TGD2"), e.tgd_s[1]);                    // DF514 TGD2, s
  io(u(515, 1, "health"), w.health);                            // DF515 SatH1
}

/// 1045 Galileo F/NAV (496 bits) and 1046 I/NAV (504 bits) ephemerides.
template <class Io, class Eph, class Wire>
constexpr void galileo_ephemeris_fields(Io& io, Eph& e, Wire& w) {
  constexpr Unit kSc = Unit::Semicircle;
  io(u(2, 12), w.number);                                       // DF002 message number
  io(u(252, 6, "satellite id"), w.prn);                         // DF252 satellite id
  io(u(289, 12), w.week);                                       // DF289 week number
  io(u(290, 10, "IODnav"), e.iode);                             // DF290 IODnav
  io(u(291, 8, "SISA"), w.accuracy);                            // DF291 SISA index
  io(s(292, 14, p2(-43), "IDOT", kSc), e.idot_radps);           // DF292 IDOT
  io(u(293, 14, 60.0, "toc"), w.toc_s);                         // DF293 toc, s
  io(s(294, 6, p2(-59), "af2"), e.af2_sps2);                    // DF294 af2
  io(s(295, 21, p2(-46), "af1"), e.af1_sps);                    // DF295 af1
  io(s(296, 31, p2(-34), "af0"), e.af0_s);                      // DF296 af0
  io(s(297, 16, p2(-5), "Crs"), e.crs_m);                       // DF297 Crs
  io(s(298, 16, p2(-43), "delta n", kSc), e.delta_n_radps);     // DF298 delta n
  io(s(299, 32, p2(-31), "M0", kSc), e.m0_rad);                 // DF299 M0
  io(s(300, 16, p2(-29), "Cuc"), e.cuc_rad);                    // DF300 Cuc
  io(u(301, 32, p2(-33), "e"), e.e);                            // DF301 eccentricity
  io(s(302, 16, p2(-29), "Cus"), e.cus_rad);                    // DF302 Cus
  io(u(303, 32, p2(-19), "sqrt A"), e.sqrt_a_sqrtm);            // DF303 sqrt A
  io(u(304, 14, 60.0, "toe"), e.toe_sow_s);                     // DF304 toe, s
  io(s(305, 16, p2(-29), "Cic"), e.cic_rad);                    // DF305 Cic
  io(s(306, 32, p2(-31), "OMEGA0", kSc), e.omega0_rad);         // DF306 OMEGA0
  io(s(307, 16, p2(-29), "Cis"), e.cis_rad);                    // DF307 Cis
  io(s(308, 32, p2(-31), "i0", kSc), e.i0_rad);                 // DF308 i0
  io(s(309, 16, p2(-5), "Crc"), e.crc_m);                       // DF309 Crc
  io(s(310, 32, p2(-31), "omega", kSc), e.omega_rad);           // DF310 omega
  io(s(311, 24, p2(-43), "OMEGADOT", kSc), e.omega_dot_radps);  // DF311 OMEGADOT
  io(s(312, 10, p2(-32), "BGD E5a/E1"), e.tgd_s[0]);            // DF312 BGD E5a/E1, s
  if (w.number == 1045) {
    io(u(314, 2), w.e5a_health);    // DF314 E5a signal health status
    io(u(315, 1), w.e5a_validity);  // DF315 E5a data validity status
    io(reserved(7));                // DF001 reserved
  } else {
    io(s(313, 10, p2(-32), "BGD E5b/E1"), e.tgd_s[1]);  // DF313 BGD E5b/E1, s
    io(u(316, 2), w.e5b_health);                        // DF316 E5b signal health status
    io(u(317, 1), w.e5b_validity);                      // DF317 E5b data validity status
    io(u(287, 2), w.e1b_health);                        // DF287 E1-B signal health status
    io(u(288, 1), w.e1b_validity);                      // DF288 E1-B data validity status
    io(reserved(2));                                    // DF001 reserved
  }
}

/// The layout of Kepler ephemeris message w.number; false if it is none.
template <class Io, class Eph, class Wire>
constexpr bool kepler_ephemeris_fields(Io& io, Eph& e, Wire& w) {
  switch (w.number) {
    case 1019: gps_ephemeris_fields(io, e, w); return true;
    case 1044: qzss_ephemeris_fields(io, e, w); return true;
    case 1042: beidou_ephemeris_fields(io, e, w); return true;
    case 1045:
    case 1046: galileo_ephemeris_fields(io, e, w); return true;
    default: return false;
  }
}

/// 1020 values that GlonassEphemeris holds otherwise.
struct GlonassWire {
  int slot = 0;            ///< DF038
  int channel = 0;         ///< DF040: frequency channel + 7
  long long tk_hours = 0;  ///< DF107 tk: hours, minutes, 30-second interval (Moscow time of day)
  long long tk_minutes = 0;
  long long tk_half_minute = 0;
  int bn_msb = 0;            ///< DF108 MSB of Bn: unhealthy
  long long tb_odd = 0;      ///< DF109 P2
  long long tb = 0;          ///< DF110: 15-minute interval of the Moscow day
  long long day_number = 0;  ///< DF129 N_T: day within the four-year period starting with a leap year
};

/// 1020 GLONASS ephemeris, 360 bits. Values in m, m/s, m/s^2 (sent in km).
template <class Io, class Eph, class Wire>
constexpr void glonass_ephemeris_fields(Io& io, Eph& g, Wire& w) {
  constexpr Unit kKm = Unit::Kilometre;
  io(unused(2, 12, 1020));                                      // DF002 message number
  io(u(38, 6, "satellite id"), w.slot);                         // DF038 satellite id (slot)
  io(u(40, 5, "frequency channel"), w.channel);                 // DF040 frequency channel number + 7
  io(unused(104, 1));                                           // DF104 almanac health
  io(unused(105, 1));                                           // DF105 almanac health availability indicator
  io(unused(106, 2));                                           // DF106 P1
  io(u(107, 5, "tk hours"), w.tk_hours);                        // DF107 tk: hours
  io(u(107, 6, "tk minutes"), w.tk_minutes);                    //        minutes
  io(u(107, 1, "tk 30 s"), w.tk_half_minute);                   //        30-second interval
  io(u(108, 1), w.bn_msb);                                      // DF108 MSB of Bn
  io(u(109, 1), w.tb_odd);                                      // DF109 P2
  io(u(110, 7, "tb"), w.tb);                                    // DF110 tb
  io(sm(111, 24, p2(-20), "velocity", kKm), g.v_E_mps[0]);      // DF111 xn'(tb), km/s
  io(sm(112, 27, p2(-11), "position", kKm), g.p_E_m[0]);        // DF112 xn(tb), km
  io(sm(113, 5, p2(-30), "acceleration", kKm), g.a_E_mps2[0]);  // DF113 xn''(tb), km/s^2
  io(sm(114, 24, p2(-20), "velocity", kKm), g.v_E_mps[1]);      // DF114 yn'(tb)
  io(sm(115, 27, p2(-11), "position", kKm), g.p_E_m[1]);        // DF115 yn(tb)
  io(sm(116, 5, p2(-30), "acceleration", kKm), g.a_E_mps2[1]);  // DF116 yn''(tb)
  io(sm(117, 24, p2(-20), "velocity", kKm), g.v_E_mps[2]);      // DF117 zn'(tb)
  io(sm(118, 27, p2(-11), "position", kKm), g.p_E_m[2]);        // DF118 zn(tb)
  io(sm(119, 5, p2(-30), "acceleration", kKm), g.a_E_mps2[2]);  // DF119 zn''(tb)
  io(unused(120, 1));                                           // DF120 P3
  io(sm(121, 11, p2(-40), "gamma_n"), g.gamma_n);               // DF121 gamma_n(tb)
  io(unused(122, 2));                                           // DF122 P
  io(unused(123, 1));                                           // DF123 ln (third string)
  io(sm(124, 22, p2(-30), "tau_n", Unit::Negated), g.tau_n_s);  // DF124 tau_n(tb), s (canyon keeps -tau_n)
  io(sm(125, 5, p2(-30), "delta tau_n"), g.delta_tau_n_s);      // DF125 delta tau_n, s
  io(u(126, 5, "E_n"), g.age_days);                             // DF126 E_n, days
  io(unused(127, 1));                                           // DF127 P4
  io(unused(128, 4));                                           // DF128 F_T
  io(u(129, 11, "N_T"), w.day_number);                          // DF129 N_T
  io(unused(130, 2, 1));                                        // DF130 M: GLONASS-M
  io(unused(131, 1));                                           // DF131 additional data (DF132-DF135) not valid
  io(unused(132, 11));                                          // DF132 N^A
  io(unused(133, 32));                                          // DF133 tau_c
  io(unused(134, 5));                                           // DF134 N_4
  io(unused(135, 22));                                          // DF135 tau_GPS
  io(unused(136, 1));                                           // DF136 ln (fifth string)
  io(reserved(7));                                              // DF001 reserved
}

// ---------------------------------------------------------------------------------------------------------------
// Legacy observations (decode only): 1004 GPS and 1012 GLONASS extended L1&L2 RTK observables.

inline constexpr double kLegacyPseudorangeLsbM = 0.02;  // DF011, DF017, DF041, DF047
inline constexpr double kLegacyPhaseLsbM = 0.0005;      // DF012, DF018, DF042, DF048
inline constexpr double kLegacyCnrLsbDbhz = 0.25;       // DF015, DF020, DF045, DF050

/// Header values that LegacyObsMessage holds otherwise.
struct LegacyWire {
  int number = 0;
  int satellites = 0;  ///< DF006 / DF035
};

/// Header of 1004 (64 bits) and 1012 (61 bits).
template <class Io, class Message, class Wire>
constexpr void legacy_header_fields(Io& io, Message& m, Wire& w) {
  const bool glonass = w.number == 1012;
  io(u(2, 12), w.number);                            // DF002 message number
  io(u(3, 12), m.station_id);                        // DF003 reference station id
  io(glonass ? u(34, 27) : u(4, 30), m.epoch_time);  // DF034 GLONASS epoch time / DF004 GPS epoch time, ms
  io(u(5, 1), m.synchronous);                        // DF005 synchronous GNSS flag
  io(glonass ? u(35, 5) : u(6, 5), w.satellites);    // DF035 / DF006 number of satellites
  io(glonass ? unused(36, 1) : unused(7, 1));        // DF036 / DF007 divergence-free smoothing indicator
  io(glonass ? unused(37, 3) : unused(8, 3));        // DF037 / DF008 smoothing interval
}

/// One satellite of 1004 or 1012 as sent.
struct LegacySatelliteWire {
  int id = 0;                       ///< DF009 / DF038
  int l1_code = 0;                  ///< DF010 / DF039
  int channel = 0;                  ///< DF040: frequency channel + 7 (1012)
  double l1_pseudorange_m = 0.0;    ///< DF011 / DF041, modulo the ambiguity
  std::int64_t l1_phase = 0;        ///< DF012 / DF042: L1 phase range - L1 pseudorange (-2^19: invalid)
  int l1_lock = 0;                  ///< DF013 / DF043
  double ambiguity_m = 0.0;         ///< DF014 / DF044
  int l1_cnr = 0;                   ///< DF015 / DF045 (0: not given)
  int l2_code = 0;                  ///< DF016 / DF046
  std::int64_t l2_pseudorange = 0;  ///< DF017 / DF047: L2 - L1 pseudorange (-2^13: invalid)
  std::int64_t l2_phase = 0;        ///< DF018 / DF048: L2 phase range - L1 pseudorange (-2^19: invalid)
  int l2_lock = 0;                  ///< DF019 / DF049
  int l2_cnr = 0;                   ///< DF020 / DF050
};

/// One satellite of 1004 (125 bits) or 1012 (130 bits).
template <class Io, class Sat>
constexpr void legacy_satellite_fields(Io& io, bool glonass, Sat& sat) {
  constexpr double kPr = kLegacyPseudorangeLsbM;
  constexpr double kPhase = kLegacyPhaseLsbM;
  constexpr double kCnr = kLegacyCnrLsbDbhz;
  if (glonass) {
    io(u(38, 6), sat.id);                       // DF038 satellite id (slot)
    io(u(39, 1), sat.l1_code);                  // DF039 L1 code indicator
    io(u(40, 5), sat.channel);                  // DF040 frequency channel number + 7
    io(u(41, 25, kPr), sat.l1_pseudorange_m);   // DF041 L1 pseudorange, m
    io(s(42, 20, kPhase), sat.l1_phase);        // DF042 L1 phase range - L1 pseudorange
    io(u(43, 7), sat.l1_lock);                  // DF043 L1 lock time indicator
    io(u(44, 7, 599584.916), sat.ambiguity_m);  // DF044 L1 pseudorange modulus ambiguity, m
    io(u(45, 8, kCnr), sat.l1_cnr);             // DF045 L1 CNR
    io(u(46, 2), sat.l2_code);                  // DF046 L2 code indicator
    io(s(47, 14, kPr), sat.l2_pseudorange);     // DF047 L2 - L1 pseudorange difference
    io(s(48, 20, kPhase), sat.l2_phase);        // DF048 L2 phase range - L1 pseudorange
    io(u(49, 7), sat.l2_lock);                  // DF049 L2 lock time indicator
    io(u(50, 8, kCnr), sat.l2_cnr);             // DF050 L2 CNR
  } else {
    io(u(9, 6), sat.id);                        // DF009 satellite id
    io(u(10, 1), sat.l1_code);                  // DF010 L1 code indicator
    io(u(11, 24, kPr), sat.l1_pseudorange_m);   // DF011 L1 pseudorange, m
    io(s(12, 20, kPhase), sat.l1_phase);        // DF012 L1 phase range - L1 pseudorange
    io(u(13, 7), sat.l1_lock);                  // DF013 L1 lock time indicator
    io(u(14, 8, 299792.458), sat.ambiguity_m);  // DF014 L1 pseudorange modulus ambiguity, m
    io(u(15, 8, kCnr), sat.l1_cnr);             // DF015 L1 CNR
    io(u(16, 2), sat.l2_code);                  // DF016 L2 code indicator
    io(s(17, 14, kPr), sat.l2_pseudorange);     // DF017 L2 - L1 pseudorange difference
    io(s(18, 20, kPhase), sat.l2_phase);        // DF018 L2 phase range - L1 pseudorange
    io(u(19, 7), sat.l2_lock);                  // DF019 L2 lock time indicator
    io(u(20, 8, kCnr), sat.l2_cnr);             // DF020 L2 CNR
  }
}

}  // namespace canyon::io::rtcm3::fields
