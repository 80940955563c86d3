// u-blox UBX message decoding (see ubx.hpp).

#include "canyon/io/ubx.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "canyon/io/bits.hpp"

namespace canyon::io::ubx {
namespace {

using core::Constellation;

constexpr std::size_t kRawxHeader = 16;
constexpr std::size_t kRawxMeasurement = 32;
constexpr std::size_t kSfrbxHeader = 8;
constexpr std::size_t kNavPvtLength = 92;
constexpr std::size_t kNavTimeGpsLength = 16;

std::uint8_t u1(std::span<const std::uint8_t> p, std::size_t i) {
  return p[i];
}
std::uint16_t u2(std::span<const std::uint8_t> p, std::size_t i) {
  return static_cast<std::uint16_t>(p[i] | (p[i + 1] << 8));
}
std::uint32_t u4(std::span<const std::uint8_t> p, std::size_t i) {
  return std::uint32_t{p[i]} | (std::uint32_t{p[i + 1]} << 8) | (std::uint32_t{p[i + 2]} << 16) |
         (std::uint32_t{p[i + 3]} << 24);
}
std::int32_t i4(std::span<const std::uint8_t> p, std::size_t i) {
  return static_cast<std::int32_t>(u4(p, i));
}
double r4(std::span<const std::uint8_t> p, std::size_t i) {
  const std::uint32_t bits = u4(p, i);
  float f = 0.0F;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}
double r8(std::span<const std::uint8_t> p, std::size_t i) {
  const std::uint64_t bits = std::uint64_t{u4(p, i)} | (std::uint64_t{u4(p, i + 4)} << 32);
  double d = 0.0;
  std::memcpy(&d, &bits, sizeof d);
  return d;
}

void put_u2(std::vector<std::uint8_t>& out, std::uint32_t v) {
  out.push_back(static_cast<std::uint8_t>(v));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}
void put_u4(std::vector<std::uint8_t>& out, std::uint32_t v) {
  put_u2(out, v & 0xFFFF);
  put_u2(out, v >> 16);
}
void put_r8(std::vector<std::uint8_t>& out, double d) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &d, sizeof d);
  put_u4(out, static_cast<std::uint32_t>(bits));
  put_u4(out, static_cast<std::uint32_t>(bits >> 32));
}
void put_r4(std::vector<std::uint8_t>& out, double d) {
  const auto f = static_cast<float>(d);
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof f);
  put_u4(out, bits);
}

}  // namespace

std::vector<std::uint8_t> frame_ubx(std::uint8_t cls, std::uint8_t id, std::span<const std::uint8_t> payload) {
  std::vector<std::uint8_t> out = {0xB5, 0x62, cls, id};
  put_u2(out, static_cast<std::uint32_t>(payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
  std::uint8_t a = 0;
  std::uint8_t b = 0;
  for (std::size_t i = 2; i < out.size(); ++i) {
    a = static_cast<std::uint8_t>(a + out[i]);
    b = static_cast<std::uint8_t>(b + a);
  }
  out.push_back(a);
  out.push_back(b);
  return out;
}

std::optional<core::SatelliteId> satellite(int gnss_id, int sv_id) {
  core::SatelliteId sat;
  switch (gnss_id) {
    case 0: sat = {Constellation::Gps, static_cast<std::uint8_t>(sv_id)}; break;
    case 2: sat = {Constellation::Galileo, static_cast<std::uint8_t>(sv_id)}; break;
    case 3: sat = {Constellation::BeiDou, static_cast<std::uint8_t>(sv_id)}; break;
    case 5: sat = {Constellation::Qzss, static_cast<std::uint8_t>(sv_id)}; break;
    case 6:
      if (sv_id == 255) return std::nullopt;  // GLONASS slot unknown
      sat = {Constellation::Glonass, static_cast<std::uint8_t>(sv_id)};
      break;
    default: return std::nullopt;  // SBAS (1), IMES (4), IRNSS (7)
  }
  if (sv_id < 0 || sv_id > 255 || !sat.valid()) return std::nullopt;
  return sat;
}

std::optional<core::SignalCode> signal_code(int gnss_id, int sig_id, int rawx_version) {
  using core::SignalCode;
  if (rawx_version == 0) {
    switch (gnss_id) {
      case 0:
      case 5:
      case 6: return SignalCode{'1', 'C'};
      case 2: return SignalCode{'1', 'X'};
      case 3: return SignalCode{'2', 'I'};
      default: return std::nullopt;
    }
  }
  switch (gnss_id) {
    case 0:
      switch (sig_id) {
        case 0: return SignalCode{'1', 'C'};
        case 3: return SignalCode{'2', 'L'};
        case 4: return SignalCode{'2', 'S'};
        case 6: return SignalCode{'5', 'I'};
        case 7: return SignalCode{'5', 'Q'};
        default: return std::nullopt;
      }
    case 2:
      switch (sig_id) {
        case 0: return SignalCode{'1', 'C'};
        case 1: return SignalCode{'1', 'B'};
        case 3: return SignalCode{'5', 'I'};
        case 4: return SignalCode{'5', 'Q'};
        case 5: return SignalCode{'7', 'I'};
        case 6: return SignalCode{'7', 'Q'};
        default: return std::nullopt;
      }
    case 3:
      switch (sig_id) {
        case 0:
        case 1: return SignalCode{'2', 'I'};
        case 2:
        case 3: return SignalCode{'7', 'I'};
        case 5: return SignalCode{'1', 'P'};
        case 7: return SignalCode{'5', 'P'};
        default: return std::nullopt;
      }
    case 5:
      switch (sig_id) {
        case 0: return SignalCode{'1', 'C'};
        case 1: return SignalCode{'1', 'Z'};
        case 4: return SignalCode{'2', 'S'};
        case 5: return SignalCode{'2', 'L'};
        case 8: return SignalCode{'5', 'I'};
        case 9: return SignalCode{'5', 'Q'};
        default: return std::nullopt;
      }
    case 6:
      switch (sig_id) {
        case 0: return SignalCode{'1', 'C'};
        case 2: return SignalCode{'2', 'C'};
        default: return std::nullopt;
      }
    default: return std::nullopt;
  }
}

Result<Rawx> decode_rawx(std::span<const std::uint8_t> p) {
  if (p.size() < kRawxHeader)
    return Error{"UBX RXM-RAWX: " + std::to_string(p.size()) + " bytes, shorter than its header"};
  Rawx r;
  r.rcv_tow_s = r8(p, 0);
  r.week = u2(p, 8);
  r.leap_s = u1(p, 10) >= 128 ? u1(p, 10) - 256 : u1(p, 10);
  const std::size_t n = u1(p, 11);
  r.rec_stat = u1(p, 12);
  r.version = u1(p, 13);
  if (p.size() != kRawxHeader + n * kRawxMeasurement) {
    return Error{"UBX RXM-RAWX: " + std::to_string(p.size()) + " bytes for " + std::to_string(n) +
                 " measurements (needs " + std::to_string(kRawxHeader + n * kRawxMeasurement) + ")"};
  }
  if (!(r.rcv_tow_s >= 0.0 && r.rcv_tow_s < core::kSecondsPerWeek + 1.0)) {
    return Error{"UBX RXM-RAWX: receiver time of week out of range"};
  }
  r.measurements.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t o = kRawxHeader + k * kRawxMeasurement;
    RawxMeasurement m;
    m.pseudorange_m = r8(p, o);
    m.carrier_phase_cyc = r8(p, o + 8);
    m.doppler_hz = r4(p, o + 16);
    m.gnss_id = u1(p, o + 20);
    m.sv_id = u1(p, o + 21);
    m.sig_id = u1(p, o + 22);
    m.freq_id = u1(p, o + 23);
    m.lock_time_ms = u2(p, o + 24);
    m.cno_dbhz = u1(p, o + 26);
    m.pr_stdev_m = 0.01 * std::ldexp(1.0, u1(p, o + 27) & 0x0F);
    m.cp_stdev = u1(p, o + 28) & 0x0F;
    m.do_stdev_hz = 0.002 * std::ldexp(1.0, u1(p, o + 29) & 0x0F);
    m.trk_stat = u1(p, o + 30);
    r.measurements.push_back(m);
  }
  return r;
}

std::vector<std::uint8_t> encode_rawx(const Rawx& r) {
  std::vector<std::uint8_t> out;
  put_r8(out, r.rcv_tow_s);
  put_u2(out, static_cast<std::uint32_t>(r.week));
  out.push_back(static_cast<std::uint8_t>(r.leap_s));
  out.push_back(static_cast<std::uint8_t>(r.measurements.size()));
  out.push_back(r.rec_stat);
  out.push_back(static_cast<std::uint8_t>(r.version));
  put_u2(out, 0);
  for (const RawxMeasurement& m : r.measurements) {
    put_r8(out, m.pseudorange_m);
    put_r8(out, m.carrier_phase_cyc);
    put_r4(out, m.doppler_hz);
    out.push_back(static_cast<std::uint8_t>(m.gnss_id));
    out.push_back(static_cast<std::uint8_t>(m.sv_id));
    out.push_back(static_cast<std::uint8_t>(m.sig_id));
    out.push_back(static_cast<std::uint8_t>(m.freq_id));
    put_u2(out, static_cast<std::uint32_t>(m.lock_time_ms));
    out.push_back(static_cast<std::uint8_t>(m.cno_dbhz));
    out.push_back(static_cast<std::uint8_t>(std::lround(std::log2(std::max(m.pr_stdev_m, 0.01) / 0.01))));
    out.push_back(static_cast<std::uint8_t>(m.cp_stdev));
    out.push_back(static_cast<std::uint8_t>(std::lround(std::log2(std::max(m.do_stdev_hz, 0.002) / 0.002))));
    out.push_back(m.trk_stat);
    out.push_back(0);
  }
  return out;
}

Result<Sfrbx> decode_sfrbx(std::span<const std::uint8_t> p) {
  if (p.size() < kSfrbxHeader)
    return Error{"UBX RXM-SFRBX: " + std::to_string(p.size()) + " bytes, shorter than its header"};
  Sfrbx s;
  s.gnss_id = u1(p, 0);
  s.sv_id = u1(p, 1);
  s.sig_id = u1(p, 2);
  s.freq_id = u1(p, 3);
  const std::size_t n = u1(p, 4);
  s.version = u1(p, 6);
  if (p.size() != kSfrbxHeader + 4 * n) {
    return Error{"UBX RXM-SFRBX: " + std::to_string(p.size()) + " bytes for " + std::to_string(n) + " words"};
  }
  s.words.reserve(n);
  for (std::size_t k = 0; k < n; ++k) s.words.push_back(u4(p, kSfrbxHeader + 4 * k));
  return s;
}

std::vector<std::uint8_t> encode_sfrbx(const Sfrbx& s) {
  std::vector<std::uint8_t> out = {static_cast<std::uint8_t>(s.gnss_id),      static_cast<std::uint8_t>(s.sv_id),
                                   static_cast<std::uint8_t>(s.sig_id),       static_cast<std::uint8_t>(s.freq_id),
                                   static_cast<std::uint8_t>(s.words.size()), 0,
                                   static_cast<std::uint8_t>(s.version),      0};
  for (const std::uint32_t w : s.words) put_u4(out, w);
  return out;
}

Result<NavPvt> decode_nav_pvt(std::span<const std::uint8_t> p) {
  if (p.size() < kNavPvtLength) return Error{"UBX NAV-PVT: " + std::to_string(p.size()) + " bytes, needs 92"};
  NavPvt v;
  v.itow_ms = u4(p, 0);
  v.year = u2(p, 4);
  v.month = u1(p, 6);
  v.day = u1(p, 7);
  v.hour = u1(p, 8);
  v.minute = u1(p, 9);
  v.second = u1(p, 10);
  v.valid = u1(p, 11);
  v.nano_ns = i4(p, 16);
  v.fix_type = u1(p, 20);
  v.flags = u1(p, 21);
  v.num_sv = u1(p, 23);
  v.lon_deg = i4(p, 24) * 1e-7;
  v.lat_deg = i4(p, 28) * 1e-7;
  v.height_m = i4(p, 32) * 1e-3;
  v.height_msl_m = i4(p, 36) * 1e-3;
  v.h_acc_m = u4(p, 40) * 1e-3;
  v.v_acc_m = u4(p, 44) * 1e-3;
  for (std::size_t i = 0; i < 3; ++i) v.vel_ned_mps[i] = i4(p, 48 + 4 * i) * 1e-3;
  v.pdop = u2(p, 76) * 0.01;
  return v;
}

Result<NavTimeGps> decode_nav_timegps(std::span<const std::uint8_t> p) {
  if (p.size() < kNavTimeGpsLength) return Error{"UBX NAV-TIMEGPS: " + std::to_string(p.size()) + " bytes, needs 16"};
  NavTimeGps t;
  t.itow_ms = u4(p, 0);
  t.ftow_ns = i4(p, 4);
  t.week = static_cast<std::int16_t>(u2(p, 8));
  t.leap_s = u1(p, 10) >= 128 ? u1(p, 10) - 256 : u1(p, 10);
  t.valid = u1(p, 11);
  t.t_acc_ns = u4(p, 12);
  return t;
}

}  // namespace canyon::io::ubx

namespace canyon::io {

namespace {
constexpr int kMaxValidCpStdev = 5;  // 0.02 cycle
}  // namespace

UbxDecoder::UbxDecoder(UbxDecoderOptions options) : options_(std::move(options)) {}

void UbxDecoder::warn_once(const std::string& text) {
  if (warned_.insert(text).second) warnings_.push_back(text);
}

std::vector<std::pair<int, int>> UbxDecoder::glonass_channels() const {
  return {glonass_channel_.begin(), glonass_channel_.end()};
}

std::optional<core::ObsEpoch> UbxDecoder::pop_epoch() {
  if (ready_head_ >= ready_.size()) {
    ready_.clear();
    ready_head_ = 0;
    return std::nullopt;
  }
  return std::move(ready_[ready_head_++]);
}

Status UbxDecoder::add_rawx(const ubx::Rawx& r, Message& out) {
  core::ObsEpoch epoch;
  epoch.time = core::GpsTime{r.week, r.rcv_tow_s}.normalized();
  out.time = epoch.time;
  time_ = epoch.time;
  for (const ubx::RawxMeasurement& m : r.measurements) {
    const auto sat = ubx::satellite(m.gnss_id, m.sv_id);
    const auto code = ubx::signal_code(m.gnss_id, m.sig_id, r.version);
    if (!sat || !code) continue;
    int channel = core::kNoGlonassChannel;
    if (sat->system == core::Constellation::Glonass && m.freq_id <= 13) {
      channel = m.freq_id - 7;
      glonass_channel_[sat->prn] = channel;
    }
    core::SignalObs sig;
    sig.code = *code;
    if ((m.trk_stat & 0x01) != 0 && m.pseudorange_m != 0.0) sig.pseudorange_m = m.pseudorange_m;
    const bool phase_valid = (m.trk_stat & 0x02) != 0 && m.cp_stdev <= kMaxValidCpStdev && m.carrier_phase_cyc != 0.0 &&
                             m.carrier_phase_cyc != -0.5;
    sig.doppler_hz = m.doppler_hz;
    if (m.cno_dbhz > 0) sig.snr_dbhz = m.cno_dbhz;
    SignalState& state = signals_[{sat->index(), code->band, code->attribute}];
    const bool half_subtracted = (m.trk_stat & 0x08) != 0;
    // The first epoch of a signal starts an arc: loss of lock, as for a lock time of zero.
    const bool slip = !state.seen || m.lock_time_ms == 0 || m.lock_time_ms < state.lock_time_ms ||
                      half_subtracted != state.half_subtracted;
    if (slip) state.pending_slip = true;
    state.lock_time_ms = m.lock_time_ms;
    state.half_subtracted = half_subtracted;
    state.seen = true;
    if (phase_valid) {
      sig.carrier_phase_cyc = m.carrier_phase_cyc;
      if (state.pending_slip) sig.lli |= core::kLliLossOfLock;
      state.pending_slip = false;
      if ((m.trk_stat & 0x04) == 0) sig.lli |= core::kLliHalfCycle;
    }
    core::SatelliteObs* so = nullptr;
    for (core::SatelliteObs& s : epoch.sats) {
      if (s.sat == *sat) so = &s;
    }
    if (so == nullptr) {
      epoch.sats.push_back(core::SatelliteObs{*sat, {}});
      so = &epoch.sats.back();
    }
    if (so->find(*code) != nullptr) continue;
    so->signals.push_back(sig);
  }
  std::sort(epoch.sats.begin(), epoch.sats.end(),
            [](const core::SatelliteObs& a, const core::SatelliteObs& b) { return a.sat < b.sat; });
  ready_.push_back(std::move(epoch));
  return Ok{};
}

Status UbxDecoder::add_sfrbx(const ubx::Sfrbx& s, Message& out) {
  std::optional<core::GpsTime> reference = time_;
  if (!reference && timegps_ && (timegps_->valid & 3) == 3) reference = timegps_->time();
  if (!reference) reference = options_.reference_time;
  if (!reference) {
    warn_once("navigation words before the first receiver time (RXM-RAWX or NAV-TIMEGPS) dropped");
    return Ok{};
  }
  const auto sat = ubx::satellite(s.gnss_id, s.sv_id);
  if (!sat) return Ok{};
  auto note = [&](const Error& e) {
    ++rejected_words_;
    warn_once(e.message);
  };
  switch (sat->system) {
    case core::Constellation::Gps:
    case core::Constellation::Qzss: {
      if (s.words.size() != 10) return Ok{};  // L2C/L5 CNAV words are not decoded
      navmsg::LnavAssembler::Subframe f{};
      for (std::size_t k = 0; k < 10; ++k) {
        const std::uint32_t data = (s.words[k] >> 6) & 0xFFFFFF;
        f[3 * k] = static_cast<std::uint8_t>(data >> 16);
        f[3 * k + 1] = static_cast<std::uint8_t>(data >> 8);
        f[3 * k + 2] = static_cast<std::uint8_t>(data);
      }
      auto r = lnav_.add(*sat, f, *reference);
      if (lnav_.klobuchar()) nav_.gps_klobuchar = lnav_.klobuchar();
      if (!r) {
        note(r.error());
      } else if (*r) {
        nav_.kepler.push_back(**r);
        ++out.new_ephemerides;
      }
      break;
    }
    case core::Constellation::Glonass: {
      if (s.words.size() != 4) return Ok{};
      navmsg::GlonassAssembler::String str{};
      for (std::size_t i = 0; i < str.size(); ++i)
        str[i] = static_cast<std::uint8_t>(s.words[i / 4] >> (24 - 8 * (i % 4)));
      str[10] &= 0xF8;  // 85 bits: the first five of byte 10
      const int channel = s.freq_id <= 13 ? s.freq_id - 7 : core::kNoGlonassChannel;
      if (channel != core::kNoGlonassChannel) glonass_channel_[sat->prn] = channel;
      auto r = glonass_.add(sat->prn, channel, str, *reference, options_.leaps);
      if (!r) {
        note(r.error());
      } else if (*r) {
        nav_.glonass.push_back(**r);
        ++out.new_ephemerides;
      }
      break;
    }
    case core::Constellation::Galileo: {
      if (s.words.size() != 8) return Ok{};
      std::array<std::uint32_t, 8> words{};
      std::copy(s.words.begin(), s.words.end(), words.begin());
      auto word = navmsg::GalileoInavAssembler::word_from_pages(words);
      if (!word) {
        note(Error{sat->to_string() + ": " + word.error().message});
        return Ok{};
      }
      if (!*word) return Ok{};
      auto r = galileo_.add(sat->prn, **word, *reference);
      if (!r) {
        note(r.error());
      } else if (*r) {
        nav_.kepler.push_back(**r);
        ++out.new_ephemerides;
      }
      break;
    }
    case core::Constellation::BeiDou: {
      if (s.words.size() != 10) return Ok{};
      if (navmsg::BeidouD1Assembler::is_geo(sat->prn)) {
        warn_once("BeiDou GEO (D2) navigation pages are not decoded");
        return Ok{};
      }
      navmsg::BeidouD1Assembler::Subframe f{};
      std::vector<std::uint8_t> bits;
      BitWriter w(bits);
      for (const std::uint32_t word : s.words) w.u(word & 0x3FFFFFFF, 30);
      w.flush();
      std::copy(bits.begin(), bits.end(), f.begin());
      auto r = beidou_.add(sat->prn, f, *reference);
      if (!r) {
        note(r.error());
      } else if (*r) {
        nav_.kepler.push_back(**r);
        ++out.new_ephemerides;
      }
      break;
    }
  }
  return Ok{};
}

Result<UbxDecoder::Message> UbxDecoder::decode(std::uint8_t cls, std::uint8_t id,
                                               std::span<const std::uint8_t> payload) {
  Message out;
  out.cls = cls;
  out.id = id;
  if (cls == ubx::kClassRxm && id == ubx::kIdRxmRawx) {
    auto r = ubx::decode_rawx(payload);
    if (!r) return r.error();
    out.content = Content::Observations;
    if (Status s = add_rawx(*r, out); !s.ok()) return s.error();
  } else if (cls == ubx::kClassRxm && id == ubx::kIdRxmSfrbx) {
    auto r = ubx::decode_sfrbx(payload);
    if (!r) return r.error();
    out.content = Content::NavigationWords;
    if (Status s = add_sfrbx(*r, out); !s.ok()) return s.error();
  } else if (cls == ubx::kClassNav && id == ubx::kIdNavPvt) {
    auto r = ubx::decode_nav_pvt(payload);
    if (!r) return r.error();
    out.content = Content::NavPvt;
    pvt_ = *r;
  } else if (cls == ubx::kClassNav && id == ubx::kIdNavTimeGps) {
    auto r = ubx::decode_nav_timegps(payload);
    if (!r) return r.error();
    out.content = Content::NavTimeGps;
    timegps_ = *r;
    if ((r->valid & 3) == 3) out.time = r->time();
  }
  ++counts_[{cls, id}];
  return out;
}

}  // namespace canyon::io
