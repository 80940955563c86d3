// RtcmFrame adapter (see rtcm_frame.hpp).

#include "canyon/dds/rtcm_frame.hpp"

#include <chrono>

#include "canyon/io/bits.hpp"

namespace canyon::dds {
namespace {

constexpr std::size_t kMaxFrameBytes = 1029;  // idl/RtcmFrame.idl bound: 3 + 1023 + 3

}  // namespace

msg::RtcmFrame to_msg(const base::BaseFrame& frame) {
  msg::RtcmFrame m;
  m.sequence_number(frame.sequence);
  m.message_number(static_cast<std::uint16_t>(frame.message_number));
  m.station_id(static_cast<std::uint16_t>(frame.station_id));
  if (frame.epoch_time) {
    m.gps_week(frame.epoch_time->week);
    m.gps_tow_s(frame.epoch_time->tow_s);
  }
  m.bytes(frame.bytes);
  m.receive_monotonic_ns(frame.receive_ns);
  return m;
}

Result<base::BaseFrame> from_msg(const msg::RtcmFrame& m) {
  const std::string which = "RtcmFrame " + std::to_string(m.sequence_number());
  const std::vector<std::uint8_t>& b = m.bytes();
  if (b.size() > kMaxFrameBytes) return Error{which + ": " + std::to_string(b.size()) + " bytes exceed 1029"};
  if (b.size() < 6 || b[0] != 0xD3 || (b[1] & 0xFC) != 0) return Error{which + ": not an RTCM 3 frame"};
  const std::size_t length = (static_cast<std::size_t>(b[1] & 3) << 8) | b[2];
  if (b.size() != length + 6) return Error{which + ": frame length " + std::to_string(length) + " does not match"};
  const std::uint32_t crc = (std::uint32_t{b[length + 3]} << 16) | (std::uint32_t{b[length + 4]} << 8) | b[length + 5];
  if (io::crc24q({b.data(), length + 3}) != crc) return Error{which + ": CRC-24Q mismatch"};
  base::BaseFrame f;
  f.sequence = m.sequence_number();
  f.message_number = m.message_number();
  f.station_id = m.station_id();
  if (m.gps_week() != 0 || m.gps_tow_s() != 0.0) f.epoch_time = core::GpsTime{m.gps_week(), m.gps_tow_s()};
  f.bytes = b;
  f.receive_ns = m.receive_monotonic_ns();
  return f;
}

bool publish_rtcm_frame(RtcmWriter& writer, const base::BaseFrame& frame) {
  msg::RtcmFrame m = to_msg(frame);
  m.send_monotonic_ns(core::pipeline_now_ns());
  m.send_unix_ns(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
  return writer.write(m);
}

}  // namespace canyon::dds
