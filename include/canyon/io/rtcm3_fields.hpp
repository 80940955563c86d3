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
// Station messages.

/// 1005/1006 values that StationPosition holds otherwise.
struct StationWire {
  int number = 1005;
  double antenna_height_m = 0.0;  ///< 1006
};

/// 1005 stationary antenna reference point, 1006 with the antenna height.
template <class Io, class Station, class Wire>
constexpr void station_position_fields(Io& io, Station& st, Wire& w) {
  io(u(2, 12), w.number);                     // DF002 message number
  io(u(3, 12), st.station_id);                // DF003 reference station id
  io(u(21, 6), st.itrf_year);                 // DF021 ITRF realization year
  io(u(22, 1), st.gps);                       // DF022 GPS indicator
  io(u(23, 1), st.glonass);                   // DF023 GLONASS indicator
  io(u(24, 1), st.galileo);                   // DF024 Galileo indicator
  io(u(141, 1), st.reference_station);        // DF141 reference-station indicator
  io(s(25, 38, 1e-4, "ARP"), st.arp_E_m[0]);  // DF025 antenna reference point ECEF-X, m
  io(u(142, 1), st.single_oscillator);        // DF142 single receiver oscillator indicator
  io(reserved(1));                            // DF001 reserved
  io(s(26, 38, 1e-4, "ARP"), st.arp_E_m[1]);  // DF026 ECEF-Y, m
  io(u(364, 2), st.quarter_cycle);            // DF364 quarter cycle indicator
  io(s(27, 38, 1e-4, "ARP"), st.arp_E_m[2]);  // DF027 ECEF-Z, m
  if (w.number == 1006) {
    io(u(28, 16, 1e-4, "antenna height"), w.antenna_height_m);  // DF028 antenna height, m
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
    if ((w.mask & (8U >> i)) != 0) io(s(423 + static_cast<int>(i), 16, 0.02, "bias"), w.bias_m[i]);
  }
}

}  // namespace canyon::io::rtcm3::fields
