// RTCM 3 station messages: 1005/1006 (antenna reference point), 1033 (receiver and antenna descriptors, also 1007
// and 1008 read), 1230 (GLONASS code-phase biases). RTCM 10403.3 tables 3.5-3, 3.5-4, 3.5-6/7/8, 3.5-13.

#include <cmath>

#include "canyon/io/bits.hpp"
#include "canyon/io/rtcm3.hpp"
#include "canyon/io/rtcm3_fields.hpp"

namespace canyon::io::rtcm3 {
namespace {

using fields::kAntennaHeightLsbM;
using fields::kArpLsbM;

std::string short_text(int number, std::size_t bytes) {
  return "RTCM 3 message " + std::to_string(number) + ": " + std::to_string(bytes) + " bytes, too short";
}

/// Bits of a layout with the given values (text fields: with their length).
template <class Layout>
std::size_t layout_bits(Layout&& layout) {
  fields::FieldCounter counter;
  layout(counter);
  return counter.bits();
}

}  // namespace

Status append_station_position(const StationPosition& s, std::vector<std::uint8_t>& out) {
  fields::StationWire wire;
  wire.number = s.antenna_height_m.has_value() ? 1006 : 1005;
  constexpr double kLimit = 137438953472.0;  // 2^37
  for (int i = 0; i < 3; ++i) {
    if (!(std::abs(std::round(s.arp_E_m[i] / kArpLsbM)) < kLimit))
      return Error{"RTCM 3 message " + std::to_string(wire.number) + ": ARP coordinate out of range"};
  }
  if (s.station_id < 0 || s.station_id > 4095) {
    return Error{"RTCM 3 message " + std::to_string(wire.number) + ": station id " + std::to_string(s.station_id) +
                 " outside 0-4095"};
  }
  if (s.antenna_height_m) {
    const double h = std::round(*s.antenna_height_m / kAntennaHeightLsbM);
    if (!(h >= 0.0 && h < 65536.0)) return Error{"RTCM 3 message 1006: antenna height out of range (0-6.5535 m)"};
    wire.antenna_height_m = *s.antenna_height_m;
  }
  BitWriter bits(out);
  fields::FieldWriter w(bits, wire.number);
  fields::station_position_fields(w, s, wire);
  return w.status();
}

Result<StationPosition> decode_station_position(std::span<const std::uint8_t> payload) {
  fields::StationWire wire;
  wire.number = message_number(payload);
  if (wire.number != 1005 && wire.number != 1006)
    return Error{"RTCM 3 message " + std::to_string(wire.number) + " is not 1005/1006"};
  StationPosition s;
  if (8 * payload.size() < layout_bits([&](auto& io) { fields::station_position_fields(io, s, wire); }))
    return Error{short_text(wire.number, payload.size())};
  fields::FieldReader r(payload);
  fields::station_position_fields(r, s, wire);
  if (wire.number == 1006) s.antenna_height_m = wire.antenna_height_m;
  return s;
}

Status append_antenna_info(const AntennaInfo& info, std::vector<std::uint8_t>& out) {
  if (info.station_id < 0 || info.station_id > 4095) return Error{"RTCM 3 message 1033: station id outside 0-4095"};
  int number = 1033;
  std::vector<std::uint8_t> payload;
  BitWriter bits(payload);
  fields::FieldWriter w(bits, number);
  fields::antenna_info_fields(w, info, number);
  if (Status s = w.status(); !s.ok()) return s;
  bits.flush();
  out.insert(out.end(), payload.begin(), payload.end());
  return Ok{};
}

Result<AntennaInfo> decode_antenna_info(std::span<const std::uint8_t> payload) {
  int number = message_number(payload);
  if (number != 1007 && number != 1008 && number != 1033) {
    return Error{"RTCM 3 message " + std::to_string(number) + " is not 1007/1008/1033"};
  }
  if (8 * payload.size() < 24) return Error{short_text(number, payload.size())};
  AntennaInfo info;
  fields::FieldReader<true> r(payload);
  fields::antenna_info_fields(r, info, number);
  if (!r.ok()) return Error{"RTCM 3 message " + std::to_string(number) + ": payload ends inside a descriptor"};
  return info;
}

Status append_glonass_biases(const GlonassBiases& b, std::vector<std::uint8_t>& out) {
  if (b.station_id < 0 || b.station_id > 4095) return Error{"RTCM 3 message 1230: station id outside 0-4095"};
  fields::GlonassBiasWire wire;
  for (std::size_t i = 0; i < 4; ++i) {
    if (!b.bias_m[i]) continue;
    const double q = std::round(*b.bias_m[i] / fields::kGlonassBiasLsbM);
    if (!(q > -32768.0 && q < 32768.0)) return Error{"RTCM 3 message 1230: bias out of range (+-655 m)"};
    wire.mask |= 8U >> i;
    wire.bias_m[i] = *b.bias_m[i];
  }
  BitWriter bits(out);
  fields::FieldWriter w(bits, wire.number);
  fields::glonass_bias_fields(w, b, wire);
  return w.status();
}

Result<GlonassBiases> decode_glonass_biases(std::span<const std::uint8_t> payload) {
  fields::GlonassBiasWire wire;
  wire.number = message_number(payload);
  if (wire.number != 1230) return Error{"RTCM 3 message " + std::to_string(wire.number) + " is not 1230"};
  GlonassBiases b;
  fields::FieldReader<true> r(payload);
  fields::glonass_bias_fields(r, b, wire);
  if (!r.ok()) return Error{short_text(wire.number, payload.size())};
  for (std::size_t i = 0; i < 4; ++i) {
    if ((wire.mask & (8U >> i)) != 0) b.bias_m[i] = wire.bias_m[i];
  }
  return b;
}

}  // namespace canyon::io::rtcm3
