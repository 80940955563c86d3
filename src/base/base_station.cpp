// The base station engine of `canyon base` (see base_station.hpp).

#include "canyon/base/base_station.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>
#include <thread>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/io/gnss_stream.hpp"
#include "canyon/io/rinex_nav.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/io/rtcm3_station_stream.hpp"
#include "canyon/net/serial_port.hpp"
#include "canyon/net/stream_client.hpp"
#include "canyon/net/stream_server.hpp"

namespace canyon::base {
namespace {

using Clock = std::chrono::steady_clock;
constexpr std::size_t kReadChunk = 4096;
constexpr int kSliceMs = 100;
constexpr double kFlushTimeoutS = 5.0;

std::string format_epoch(const core::GpsTime& t) {
  const core::CalendarTime c = core::gps_to_calendar(t);
  char text[48];
  std::snprintf(text, sizeof text, "%04d-%02d-%02d %02d:%02d:%06.3f", c.year, c.month, c.day, c.hour, c.minute,
                c.second);
  return text;
}

}  // namespace

struct BaseStation::Impl {
  std::unique_ptr<net::StreamServer> ntrip;
  std::unique_ptr<net::StreamServer> tcp;
  std::vector<BaseFrameSink> sinks;
  std::function<int()> subscriber_count;
  std::unique_ptr<io::Rtcm3StationStream> stream;
  bool station_set = false;
  // File inputs, read at creation so that a bad file fails before any output starts.
  std::optional<io::RinexObsFile> rinex;
  core::NavigationData rinex_nav;
  std::vector<std::uint8_t> file_bytes;
  // Progress.
  mutable std::mutex stats_mutex;
  BaseStationStats stats;
  Clock::time_point last_progress = Clock::now();
  std::uint64_t sequence = 0;
  // Pacing of file replays.
  std::optional<core::GpsTime> first_epoch;
  Clock::time_point first_wall;
};

BaseStation::BaseStation(config::BaseConfig config, LogFn log)
    : config_(std::move(config)), log_(std::move(log)), impl_(std::make_unique<Impl>()) {}

BaseStation::~BaseStation() = default;

Result<std::unique_ptr<BaseStation>> BaseStation::create(config::BaseConfig config, LogFn log) {
  if (const std::string e = config.validate(); !e.empty()) return Error{"base configuration: " + e};
  std::unique_ptr<BaseStation> base(new BaseStation(std::move(config), std::move(log)));
  const config::BaseConfig& c = base->config_;
  Impl& impl = *base->impl_;
  io::Rtcm3StationStreamOptions so;
  so.encoder.station_id = c.station.id;
  so.encoder.msm_type = c.rtcm.msm;
  so.station_interval_s = c.rtcm.station_interval_s;
  so.ephemeris_interval_s = c.rtcm.ephemeris_interval_s;
  // Inputs read before the outputs start: a missing or broken file is an error now.
  if (c.input.source == config::BaseInputSource::File) {
    if (c.input.kind == config::BaseInputKind::Rinex) {
      auto obs = io::read_rinex_obs(c.input.path);
      if (!obs) return obs.error();
      if (obs->epochs.empty()) return Error{"no observation epoch", c.input.path, 0};
      so.encoder.glonass_channels = obs->header.receiver.glonass_slot_channels;
      impl.rinex = std::move(*obs);
      for (const std::string& path : c.input.nav) {
        auto nav = io::read_rinex_nav(path);
        if (!nav) return nav.error();
        impl.rinex_nav.merge(nav->nav);
      }
    } else {
      std::string warning;
      auto bytes = io::read_binary_file(c.input.path, &warning);
      if (!bytes) return bytes.error();
      if (!warning.empty()) base->log(warning);
      impl.file_bytes = std::move(*bytes);
    }
  }
  impl.stream = std::make_unique<io::Rtcm3StationStream>(so);
  if (impl.rinex) impl.stream->add_navigation(impl.rinex_nav);
  std::optional<Eigen::Vector3d> position = c.station.position_E_m;
  if (!position && impl.rinex) position = impl.rinex->header.receiver.approx_position_E_m;
  if (position) base->set_station(*position);
  if (c.station.antenna.size() + c.station.receiver.size() > 0) {
    io::rtcm3::AntennaInfo a;
    a.antenna_descriptor = c.station.antenna;
    a.receiver_type = c.station.receiver;
    impl.stream->set_antenna(a);
  }
  // Outputs.
  if (c.ntrip.enabled) {
    net::StreamServerOptions o;
    o.mode = net::StreamServerOptions::Mode::Ntrip;
    o.bind_host = c.ntrip.bind;
    o.port = c.ntrip.port;
    o.user = c.ntrip.user;
    o.password = c.ntrip.password;
    net::MountPoint m;
    m.name = c.ntrip.mountpoint;
    m.identifier = "canyon base " + std::to_string(c.station.id);
    m.format_details = "1005(" + std::to_string(static_cast<int>(c.rtcm.station_interval_s)) + "),MSM" +
                       std::to_string(c.rtcm.msm) + "(1)";
    m.nav_system = "GPS+GLO+GAL+BDS+QZS";
    m.authentication = c.ntrip.user.empty() ? "N" : "B";
    if (position) {
      const core::Geodetic g = core::ecef_to_geodetic(*position);
      m.latitude_deg = g.lat_rad * core::kRadToDeg;
      m.longitude_deg = g.lon_rad * core::kRadToDeg;
    }
    o.mounts = {m};
    auto server = net::StreamServer::start(o);
    if (!server) return Error{"NTRIP caster: " + server.error().message};
    impl.ntrip = std::move(*server);
    base->log("NTRIP caster on " + c.ntrip.bind + ":" + std::to_string(impl.ntrip->port()) + ", mount point /" +
              c.ntrip.mountpoint + (c.ntrip.user.empty() ? "" : " (Basic authentication)"));
  }
  if (c.tcp.enabled) {
    net::StreamServerOptions o;
    o.bind_host = c.tcp.bind;
    o.port = c.tcp.port;
    auto server = net::StreamServer::start(o);
    if (!server) return Error{"TCP server: " + server.error().message};
    impl.tcp = std::move(*server);
    base->log("TCP server on " + c.tcp.bind + ":" + std::to_string(impl.tcp->port()));
  }
  return base;
}

void BaseStation::log(const std::string& text) const {
  if (log_) log_(text);
}

void BaseStation::set_station(const Eigen::Vector3d& position) {
  io::rtcm3::StationPosition s;
  s.station_id = config_.station.id;
  s.arp_E_m = position;
  s.antenna_height_m = config_.station.antenna_height_m;
  impl_->stream->set_station(s);
  impl_->station_set = true;
  const core::Geodetic g = core::ecef_to_geodetic(position);
  char text[160];
  std::snprintf(text, sizeof text, "station %d at %.4f %.4f %.4f (ECEF m; %.7f %.7f deg, %.3f m)", config_.station.id,
                position.x(), position.y(), position.z(), g.lat_rad * core::kRadToDeg, g.lon_rad * core::kRadToDeg,
                g.height_m);
  log(text);
}

void BaseStation::add_sink(BaseFrameSink sink) {
  impl_->sinks.push_back(std::move(sink));
}

void BaseStation::set_subscriber_count(std::function<int()> count) {
  impl_->subscriber_count = std::move(count);
}

int BaseStation::ntrip_port() const {
  return impl_->ntrip ? impl_->ntrip->port() : 0;
}

int BaseStation::tcp_port() const {
  return impl_->tcp ? impl_->tcp->port() : 0;
}

BaseStationStats BaseStation::stats() const {
  const std::lock_guard lock(impl_->stats_mutex);
  BaseStationStats s = impl_->stats;
  if (impl_->ntrip) s.ntrip_clients = impl_->ntrip->stats().clients;
  if (impl_->tcp) s.tcp_clients = impl_->tcp->stats().clients;
  return s;
}

int BaseStation::subscribers() const {
  int n = 0;
  if (impl_->ntrip) n += impl_->ntrip->stats().clients;
  if (impl_->tcp) n += impl_->tcp->stats().clients;
  if (impl_->subscriber_count) n += impl_->subscriber_count();
  return n;
}

bool BaseStation::wait_for_clients(int clients, double timeout_s) {
  const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (!stop_requested()) {
    drain_server_events();
    if (subscribers() >= clients) {
      std::this_thread::sleep_for(std::chrono::duration<double>(kSettleS));
      return !stop_requested();
    }
    if (Clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

void BaseStation::drain_server_events() {
  if (impl_->ntrip) {
    for (const std::string& e : impl_->ntrip->take_events()) log("NTRIP: " + e);
  }
  if (impl_->tcp) {
    for (const std::string& e : impl_->tcp->take_events()) log("TCP: " + e);
  }
}

bool BaseStation::pace(const core::GpsTime& t) {
  Impl& impl = *impl_;
  if (!impl.first_epoch) {
    impl.first_epoch = t;
    impl.first_wall = Clock::now();
    return !stop_requested();
  }
  if (config_.input.pace <= 0.0 || config_.input.source != config::BaseInputSource::File) return !stop_requested();
  const auto target = impl.first_wall + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                            (t - *impl.first_epoch) / config_.input.pace));
  while (!stop_requested()) {
    const auto now = Clock::now();
    if (now >= target) break;
    std::this_thread::sleep_for(std::min<Clock::duration>(target - now, std::chrono::milliseconds(kSliceMs)));
  }
  return !stop_requested();
}

Status BaseStation::emit(const core::ObsEpoch& epoch, core::PipelineNs receive_ns) {
  Impl& impl = *impl_;
  auto frames = impl.stream->epoch(epoch);
  if (!frames) return frames.error();
  std::uint64_t bytes = 0;
  for (io::Rtcm3Frame& f : *frames) {
    BaseFrame frame;
    frame.sequence = impl.sequence++;
    frame.message_number = f.message_number;
    frame.station_id = config_.station.id;
    frame.epoch_time = epoch.time;
    frame.bytes = std::move(f.bytes);
    frame.receive_ns = receive_ns;
    if (impl.ntrip) impl.ntrip->publish(config_.ntrip.mountpoint, frame.bytes);
    if (impl.tcp) impl.tcp->publish("", frame.bytes);
    for (const BaseFrameSink& sink : impl.sinks) sink(frame);
    bytes += frame.bytes.size();
  }
  {
    const std::lock_guard lock(impl.stats_mutex);
    ++impl.stats.epochs;
    impl.stats.frames += frames->size();
    impl.stats.bytes += bytes;
    impl.stats.last_epoch = epoch.time;
  }
  drain_server_events();
  if (config_.progress_interval_s > 0.0 &&
      Clock::now() - impl.last_progress > std::chrono::duration<double>(config_.progress_interval_s)) {
    impl.last_progress = Clock::now();
    const BaseStationStats s = stats();
    char text[256];
    std::snprintf(text, sizeof text,
                  "%llu epochs, %llu frames (%.1f kB), last epoch %s GPST; NTRIP clients %d, TCP clients %d, "
                  "subscribers %d",
                  static_cast<unsigned long long>(s.epochs), static_cast<unsigned long long>(s.frames),
                  static_cast<double>(s.bytes) / 1000.0, format_epoch(epoch.time).c_str(), s.ntrip_clients,
                  s.tcp_clients, subscribers());
    log(text);
  }
  return Ok{};
}

void BaseStation::flush_outputs() {
  const auto end = Clock::now() + std::chrono::duration<double>(kFlushTimeoutS);
  while (Clock::now() < end) {
    std::size_t pending = 0;
    if (impl_->ntrip) pending += impl_->ntrip->stats().pending_bytes;
    if (impl_->tcp) pending += impl_->tcp->stats().pending_bytes;
    if (pending == 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  drain_server_events();
}

Status BaseStation::run_rinex() {
  Impl& impl = *impl_;
  for (const core::ObsEpoch& epoch : impl.rinex->epochs) {
    if (!pace(epoch.time)) break;
    if (Status s = emit(epoch, core::pipeline_now_ns()); !s.ok()) return s;
  }
  return Ok{};
}

Status BaseStation::run_bytes() {
  Impl& impl = *impl_;
  const config::BaseConfig& c = config_;
  io::GnssStreamOptions o;
  o.format = c.input.kind == config::BaseInputKind::Ubx ? io::StreamFormat::Ubx : io::StreamFormat::Rtcm3;
  o.rtcm3.reference_time = c.input.approx_time.value_or(core::system_clock_gps(core::builtin_leap_seconds()));
  io::GnssStreamDecoder decoder(o);
  std::size_t kepler_seen = 0;
  std::size_t glonass_seen = 0;
  std::uint64_t problems_seen = 0;
  // Everything new in the decoder: ephemerides, station position, epochs (paced for files).
  auto drain = [&]() -> Status {
    const core::NavigationData& nav = decoder.navigation();
    if (nav.kepler.size() > kepler_seen || nav.glonass.size() > glonass_seen) {
      core::NavigationData fresh;
      fresh.kepler.assign(nav.kepler.begin() + static_cast<std::ptrdiff_t>(kepler_seen), nav.kepler.end());
      fresh.glonass.assign(nav.glonass.begin() + static_cast<std::ptrdiff_t>(glonass_seen), nav.glonass.end());
      impl.stream->add_navigation(fresh);
      kepler_seen = nav.kepler.size();
      glonass_seen = nav.glonass.size();
    }
    if (!impl.station_set) {
      if (const auto& s = decoder.rtcm3().station()) {
        set_station(s->arp_E_m);
      } else if (const auto& pvt = decoder.ubx().nav_pvt(); pvt && pvt->fix_type >= 3 && (pvt->flags & 1) != 0) {
        set_station(core::geodetic_to_ecef(
            core::Geodetic{pvt->lat_deg * core::kDegToRad, pvt->lon_deg * core::kDegToRad, pvt->height_m}));
      }
    }
    const io::GnssStreamStats st = decoder.stats();
    const std::uint64_t problems = st.framing.bad_packets() + st.rtcm3_decode_errors + st.ubx_decode_errors;
    if (problems > problems_seen) {
      const std::lock_guard lock(impl.stats_mutex);
      impl.stats.input_problems = problems;
      problems_seen = problems;
    }
    for (;;) {
      auto epoch = c.input.kind == config::BaseInputKind::Ubx ? decoder.pop_ubx_epoch() : decoder.pop_rtcm3_epoch();
      if (!epoch) break;
      if (!pace(epoch->time)) return Ok{};
      if (Status s = emit(*epoch, core::pipeline_now_ns()); !s.ok()) return s;
    }
    return Ok{};
  };

  switch (c.input.source) {
    case config::BaseInputSource::File: {
      for (std::size_t pos = 0; pos < impl.file_bytes.size() && !stop_requested(); pos += kReadChunk) {
        decoder.push({impl.file_bytes.data() + pos, std::min(kReadChunk, impl.file_bytes.size() - pos)});
        if (Status s = drain(); !s.ok()) return s;
      }
      decoder.finish();
      if (Status s = drain(); !s.ok()) return s;
      for (const std::string& p : decoder.problems()) log("input: " + p);
      return Ok{};
    }
    case config::BaseInputSource::Serial: {
      auto port = net::SerialPort::open(c.input.path, c.input.baud);
      if (!port) return port.error();
      log("reading " + c.input.path + " at " + std::to_string(c.input.baud) + " baud");
      std::vector<std::uint8_t> buffer(kReadChunk);
      while (!stop_requested()) {
        auto n = port->read(buffer, kSliceMs);
        if (!n) return n.error();
        if (*n > 0) decoder.push({buffer.data(), *n});
        if (Status s = drain(); !s.ok()) return s;
      }
      return Ok{};
    }
    case config::BaseInputSource::Tcp:
    case config::BaseInputSource::Ntrip: {
      std::mutex mutex;
      std::condition_variable arrived;
      std::deque<std::vector<std::uint8_t>> queue;
      net::StreamClientOptions co;
      co.mode = c.input.source == config::BaseInputSource::Ntrip ? net::StreamClientOptions::Mode::Ntrip
                                                                 : net::StreamClientOptions::Mode::Tcp;
      co.host = c.input.host;
      co.port = c.input.port;
      co.mount = c.input.mountpoint;
      co.user = c.input.user;
      co.password = c.input.password;
      net::StreamClient client(
          co,
          [&](std::span<const std::uint8_t> bytes) {
            const std::lock_guard lock(mutex);
            queue.emplace_back(bytes.begin(), bytes.end());
            arrived.notify_one();
          },
          [this](const std::string& e) { log("input: " + e); });
      if (Status s = client.start(); !s.ok()) return s;
      while (!stop_requested()) {
        std::deque<std::vector<std::uint8_t>> got;
        {
          std::unique_lock lock(mutex);
          arrived.wait_for(lock, std::chrono::milliseconds(kSliceMs), [&] { return !queue.empty(); });
          got.swap(queue);
        }
        for (const auto& bytes : got) decoder.push(bytes);
        if (Status s = drain(); !s.ok()) return s;
      }
      client.stop();
      return Ok{};
    }
  }
  return Ok{};
}

Status BaseStation::run() {
  const config::BaseConfig& c = config_;
  log("input: " + config::input_kind_name(c.input.kind) + " from " + config::input_source_name(c.input.source) + " " +
      (c.input.source == config::BaseInputSource::Tcp || c.input.source == config::BaseInputSource::Ntrip
           ? c.input.host + ":" + std::to_string(c.input.port) +
                 (c.input.mountpoint.empty() ? "" : "/" + c.input.mountpoint)
           : c.input.path) +
      (c.input.source == config::BaseInputSource::File ? ", pace " + std::to_string(c.input.pace) : std::string()));
  if (!impl_->station_set) log("station position not known yet: no 1005 until the input gives one");
  Status result = impl_->rinex ? run_rinex() : run_bytes();
  flush_outputs();
  const BaseStationStats s = stats();
  char text[200];
  std::snprintf(text, sizeof text, "stopped: %llu epochs, %llu frames, %.1f kB sent; %llu input problems",
                static_cast<unsigned long long>(s.epochs), static_cast<unsigned long long>(s.frames),
                static_cast<double>(s.bytes) / 1000.0, static_cast<unsigned long long>(s.input_problems));
  log(text);
  return result;
}

}  // namespace canyon::base
