// RTCM 3 station messages: 1005/1006 (antenna reference point), 1033 (receiver and antenna descriptors, also 1007
// and 1008 read), 1230 (GLONASS code-phase biases). RTCM 10403.3 tables 3.5-3, 3.5-4, 3.5-6/7/8, 3.5-13.

#include <cmath>

#include "canyon/io/bits.hpp"
#include "canyon/io/rtcm3.hpp"

namespace canyon::io::rtcm3 {
namespace {

constexpr double kArpLsbM = 1e-4;            // DF025-027
constexpr double kAntennaHeightLsbM = 1e-4;  // DF028
constexpr double kBiasLsbM = 0.02;           // DF423-426
constexpr std::size_t kMaxDescriptor = 31;   // DF029/DF032/DF227/DF229/DF231 counters are 8 bits; RTCM limits to 31

std::string short_text(int number, std::size_t bytes) {
  return "RTCM 3 message " + std::to_string(number) + ": " + std::to_string(bytes) + " bytes, too short";
}

Status append_string(BitWriter& w, const std::string& text, const char* what) {
  if (text.size() > kMaxDescriptor) {
    return Error{std::string("RTCM 3 message 1033: ") + what + " '" + text + "' longer than 31 characters"};
  }
  w.u(text.size(), 8);
  for (const char c : text) w.u(static_cast<unsigned char>(c), 8);
  return Ok{};
}

/// Reads a counter and that many characters; false if the payload ends first.
bool read_string(BitReader& r, std::string& out) {
  if (r.bits_left() < 8) return false;
  const auto n = static_cast<std::size_t>(r.u(8));
  if (r.bits_left() < 8 * n) return false;
  out.clear();
  for (std::size_t i = 0; i < n; ++i) out.push_back(static_cast<char>(r.u(8)));
  return true;
}

}  // namespace

Status append_station_position(const StationPosition& s, std::vector<std::uint8_t>& out) {
  const bool with_height = s.antenna_height_m.has_value();
  const int number = with_height ? 1006 : 1005;
  constexpr double kLimit = 137438953472.0;  // 2^37
  std::array<std::int64_t, 3> q{};
  for (int i = 0; i < 3; ++i) {
    const double v = std::round(s.arp_E_m[i] / kArpLsbM);
    if (!(std::abs(v) < kLimit))
      return Error{"RTCM 3 message " + std::to_string(number) + ": ARP coordinate out of range"};
    q[static_cast<std::size_t>(i)] = static_cast<std::int64_t>(v);
  }
  if (s.station_id < 0 || s.station_id > 4095) {
    return Error{"RTCM 3 message " + std::to_string(number) + ": station id " + std::to_string(s.station_id) +
                 " outside 0-4095"};
  }
  BitWriter w(out);
  w.u(static_cast<std::uint64_t>(number), 12);
  w.u(static_cast<std::uint64_t>(s.station_id), 12);
  w.u(static_cast<std::uint64_t>(s.itrf_year & 0x3F), 6);
  w.u(s.gps ? 1 : 0, 1);
  w.u(s.glonass ? 1 : 0, 1);
  w.u(s.galileo ? 1 : 0, 1);
  w.u(s.reference_station ? 1 : 0, 1);
  w.s(q[0], 38);
  w.u(s.single_oscillator ? 1 : 0, 1);
  w.u(0, 1);
  w.s(q[1], 38);
  w.u(static_cast<std::uint64_t>(s.quarter_cycle & 3), 2);
  w.s(q[2], 38);
  if (with_height) {
    const double h = std::round(*s.antenna_height_m / kAntennaHeightLsbM);
    if (!(h >= 0.0 && h < 65536.0)) return Error{"RTCM 3 message 1006: antenna height out of range (0-6.5535 m)"};
    w.u(static_cast<std::uint64_t>(h), 16);
  }
  return Ok{};
}

Result<StationPosition> decode_station_position(std::span<const std::uint8_t> payload) {
  const int number = message_number(payload);
  if (number != 1005 && number != 1006) return Error{"RTCM 3 message " + std::to_string(number) + " is not 1005/1006"};
  BitReader r(payload);
  if (r.bits_left() < (number == 1006 ? 168U : 152U)) return Error{short_text(number, payload.size())};
  StationPosition s;
  r.skip(12);
  s.station_id = static_cast<int>(r.u(12));
  s.itrf_year = static_cast<int>(r.u(6));
  s.gps = r.u(1) != 0;
  s.glonass = r.u(1) != 0;
  s.galileo = r.u(1) != 0;
  s.reference_station = r.u(1) != 0;
  s.arp_E_m.x() = static_cast<double>(r.s(38)) * kArpLsbM;
  s.single_oscillator = r.u(1) != 0;
  r.skip(1);
  s.arp_E_m.y() = static_cast<double>(r.s(38)) * kArpLsbM;
  s.quarter_cycle = static_cast<int>(r.u(2));
  s.arp_E_m.z() = static_cast<double>(r.s(38)) * kArpLsbM;
  if (number == 1006) s.antenna_height_m = static_cast<double>(r.u(16)) * kAntennaHeightLsbM;
  return s;
}

Status append_antenna_info(const AntennaInfo& info, std::vector<std::uint8_t>& out) {
  if (info.station_id < 0 || info.station_id > 4095) return Error{"RTCM 3 message 1033: station id outside 0-4095"};
  std::vector<std::uint8_t> payload;
  BitWriter w(payload);
  w.u(1033, 12);
  w.u(static_cast<std::uint64_t>(info.station_id), 12);
  if (Status s = append_string(w, info.antenna_descriptor, "antenna descriptor"); !s.ok()) return s;
  w.u(static_cast<std::uint64_t>(info.antenna_setup_id & 0xFF), 8);
  if (Status s = append_string(w, info.antenna_serial, "antenna serial number"); !s.ok()) return s;
  if (Status s = append_string(w, info.receiver_type, "receiver type"); !s.ok()) return s;
  if (Status s = append_string(w, info.receiver_firmware, "receiver firmware"); !s.ok()) return s;
  if (Status s = append_string(w, info.receiver_serial, "receiver serial number"); !s.ok()) return s;
  w.flush();
  out.insert(out.end(), payload.begin(), payload.end());
  return Ok{};
}

Result<AntennaInfo> decode_antenna_info(std::span<const std::uint8_t> payload) {
  const int number = message_number(payload);
  if (number != 1007 && number != 1008 && number != 1033) {
    return Error{"RTCM 3 message " + std::to_string(number) + " is not 1007/1008/1033"};
  }
  BitReader r(payload);
  if (r.bits_left() < 24) return Error{short_text(number, payload.size())};
  AntennaInfo info;
  r.skip(12);
  info.station_id = static_cast<int>(r.u(12));
  bool ok = read_string(r, info.antenna_descriptor) && r.bits_left() >= 8;
  if (ok) info.antenna_setup_id = static_cast<int>(r.u(8));
  if (ok && number != 1007) ok = read_string(r, info.antenna_serial);
  if (ok && number == 1033) {
    ok = read_string(r, info.receiver_type) && read_string(r, info.receiver_firmware) &&
         read_string(r, info.receiver_serial);
  }
  if (!ok) return Error{"RTCM 3 message " + std::to_string(number) + ": payload ends inside a descriptor"};
  return info;
}

Status append_glonass_biases(const GlonassBiases& b, std::vector<std::uint8_t>& out) {
  if (b.station_id < 0 || b.station_id > 4095) return Error{"RTCM 3 message 1230: station id outside 0-4095"};
  BitWriter w(out);
  w.u(1230, 12);
  w.u(static_cast<std::uint64_t>(b.station_id), 12);
  w.u(b.aligned ? 1 : 0, 1);
  w.u(0, 3);
  unsigned mask = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    if (b.bias_m[i]) mask |= 8U >> i;
  }
  w.u(mask, 4);
  for (std::size_t i = 0; i < 4; ++i) {
    if (!b.bias_m[i]) continue;
    const double q = std::round(*b.bias_m[i] / kBiasLsbM);
    if (!(q > -32768.0 && q < 32768.0)) return Error{"RTCM 3 message 1230: bias out of range (+-655 m)"};
    w.s(static_cast<std::int64_t>(q), 16);
  }
  return Ok{};
}

Result<GlonassBiases> decode_glonass_biases(std::span<const std::uint8_t> payload) {
  const int number = message_number(payload);
  if (number != 1230) return Error{"RTCM 3 message " + std::to_string(number) + " is not 1230"};
  BitReader r(payload);
  if (r.bits_left() < 32) return Error{short_text(number, payload.size())};
  GlonassBiases b;
  r.skip(12);
  b.station_id = static_cast<int>(r.u(12));
  b.aligned = r.u(1) != 0;
  r.skip(3);
  const auto mask = static_cast<unsigned>(r.u(4));
  for (std::size_t i = 0; i < 4; ++i) {
    if ((mask & (8U >> i)) == 0) continue;
    if (r.bits_left() < 16) return Error{short_text(number, payload.size())};
    b.bias_m[i] = static_cast<double>(r.s(16)) * kBiasLsbM;
  }
  return b;
}

}  // namespace canyon::io::rtcm3
