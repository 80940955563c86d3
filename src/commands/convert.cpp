// `canyon convert` (see convert.hpp).

#include "canyon/commands/convert.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <mutex>
#include <thread>

#include "canyon/eval/map_tracks.hpp"
#include "canyon/io/gnss_stream.hpp"
#include "canyon/io/pos_file.hpp"
#include "canyon/io/rinex_nav.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/io/rtcm3_station_stream.hpp"
#include "canyon/net/socket.hpp"
#include "canyon/net/stream_client.hpp"
#include "canyon/net/stream_url.hpp"

namespace canyon::commands {
namespace {

/// `input` without a .gz suffix and its extension, plus `extension`.
std::string sibling(const std::string& input, const std::string& extension) {
  std::filesystem::path p(input == "-" || input.find("://") != std::string::npos ? "stream" : input);
  if (p.extension() == ".gz") p.replace_extension();
  p.replace_extension(extension);
  return p.string();
}

Result<std::vector<std::uint8_t>> record_stream(const ConvertConfig& config, const net::StreamUrl& url,
                                                std::vector<std::string>& warnings) {
  net::StreamClientOptions o;
  o.mode = url.ntrip ? net::StreamClientOptions::Mode::Ntrip : net::StreamClientOptions::Mode::Tcp;
  o.host = url.host;
  o.port = url.port;
  o.mount = url.mount;
  o.user = url.user;
  o.password = url.password;
  o.ntrip_version = config.ntrip_version;
  o.max_attempts = 3;
  o.backoff_min_s = 0.5;
  // A recording ends on its idle timeout; the client's stall detection (a reconnection) only serves a stream that
  // has not started yet or broke off, so it waits longer.
  o.stall_timeout_s = std::max(2.0 * config.idle_timeout_s, 10.0);
  std::mutex mutex;
  std::vector<std::uint8_t> bytes;
  auto last = std::chrono::steady_clock::now();
  net::StreamClient client(
      o,
      [&](std::span<const std::uint8_t> data) {
        const std::lock_guard lock(mutex);
        bytes.insert(bytes.end(), data.begin(), data.end());
        last = std::chrono::steady_clock::now();
      },
      [&](const std::string& e) {
        if (e.rfind("connected to", 0) == 0) return;  // not a problem
        const std::lock_guard lock(mutex);
        warnings.push_back(config.input + ": " + e);
      });
  if (Status s = client.start(); !s.ok()) return s.error();
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const auto now = std::chrono::steady_clock::now();
    const std::lock_guard lock(mutex);
    if (config.duration_s > 0.0 && now - start >= std::chrono::duration<double>(config.duration_s)) break;
    if (!bytes.empty() && now - last >= std::chrono::duration<double>(config.idle_timeout_s)) break;
    if (client.finished()) break;
  }
  client.stop();
  const std::string last_error = client.stats().last_error;
  const std::lock_guard lock(mutex);
  if (bytes.empty()) {
    return Error{"no data received" + (last_error.empty() ? std::string() : " (" + last_error + ")"), config.input, 0};
  }
  return bytes;
}

Result<std::vector<std::uint8_t>> read_input(const ConvertConfig& config, std::vector<std::string>& warnings) {
  auto url = net::parse_stream_url(config.input);
  if (!url) return url.error();
  if (*url) return record_stream(config, **url, warnings);
  const std::string& path = config.input;
  if (path == "-") {
    std::vector<std::uint8_t> bytes;
    char buffer[1 << 16];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, stdin)) > 0) bytes.insert(bytes.end(), buffer, buffer + n);
    return bytes;
  }
  std::string warning;
  auto bytes = io::read_binary_file(path, &warning);
  if (bytes && !warning.empty()) warnings.push_back(warning);
  return bytes;
}

bool looks_like_rinex(const std::vector<std::uint8_t>& bytes) {
  const std::size_t end = std::min<std::size_t>(bytes.size(), 81);
  const std::string first(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(end));
  return first.find("RINEX VERSION / TYPE") != std::string::npos;
}

std::string counts_line(const io::GnssStreamStats& s) {
  char text[512];
  std::snprintf(
      text, sizeof text,
      "%llu bytes: %llu RTCM 3 frames, %llu UBX packets, %llu NMEA sentences; %llu bad RTCM 3 CRCs, %llu bad "
      "UBX checksums, %llu truncated, %llu garbage bytes; %llu RTCM 3 and %llu UBX messages undecodable",
      static_cast<unsigned long long>(s.framing.bytes), static_cast<unsigned long long>(s.framing.rtcm3_frames),
      static_cast<unsigned long long>(s.framing.ubx_packets), static_cast<unsigned long long>(s.framing.nmea_sentences),
      static_cast<unsigned long long>(s.framing.rtcm3_bad_crc),
      static_cast<unsigned long long>(s.framing.ubx_bad_checksum), static_cast<unsigned long long>(s.framing.truncated),
      static_cast<unsigned long long>(s.framing.garbage_bytes), static_cast<unsigned long long>(s.rtcm3_decode_errors),
      static_cast<unsigned long long>(s.ubx_decode_errors));
  return text;
}

/// Merges consecutive epochs of the same time (within 0.5 ms) into one; a satellite given twice keeps its first.
void merge_same_time(std::vector<core::ObsEpoch>& epochs) {
  std::vector<core::ObsEpoch> merged;
  merged.reserve(epochs.size());
  for (core::ObsEpoch& e : epochs) {
    if (!merged.empty() && std::abs(merged.back().time - e.time) < 5e-4) {
      core::ObsEpoch& into = merged.back();
      for (core::SatelliteObs& s : e.sats) {
        const bool known = std::any_of(into.sats.begin(), into.sats.end(),
                                       [&](const core::SatelliteObs& o) { return o.sat == s.sat; });
        if (!known) into.sats.push_back(std::move(s));
      }
      std::sort(into.sats.begin(), into.sats.end(),
                [](const core::SatelliteObs& a, const core::SatelliteObs& b) { return a.sat < b.sat; });
      continue;
    }
    merged.push_back(std::move(e));
  }
  epochs = std::move(merged);
}

/// The first ephemeris of the stream that dates it (any toe, resolved against `now`).
std::optional<core::GpsTime> stream_date(const std::vector<std::uint8_t>& bytes, const core::GpsTime& now) {
  io::GnssStreamOptions o;
  o.rtcm3.reference_time = now;
  io::GnssStreamDecoder probe(o);
  probe.push(bytes);
  probe.finish();
  const core::NavigationData& nav = probe.navigation();
  // Prefer systems whose messages carry long weeks (Galileo, BeiDou), then GPS/QZSS, then GLONASS (day only).
  for (const core::Constellation c : {core::Constellation::Galileo, core::Constellation::BeiDou,
                                      core::Constellation::Gps, core::Constellation::Qzss}) {
    for (const core::KeplerEphemeris& e : nav.kepler) {
      if (e.sat.system == c) return e.toe;
    }
  }
  return std::nullopt;
}

Result<ConvertSummary> binary_to_rinex(const ConvertConfig& config, const std::vector<std::uint8_t>& bytes,
                                       io::StreamFormat format, std::vector<std::string> warnings) {
  ConvertSummary summary;
  io::GnssStreamOptions o;
  o.format = format;
  const core::GpsTime now = core::system_clock_gps(core::builtin_leap_seconds());
  if (config.approx_time) {
    o.rtcm3.reference_time = *config.approx_time;
  } else if (format != io::StreamFormat::Ubx) {
    const auto dated = stream_date(bytes, now);
    o.rtcm3.reference_time = dated.value_or(now);
    if (!dated) {
      warnings.emplace_back(
          "no ephemeris in the input dates it: RTCM 3 weeks are resolved against the current date "
          "(give --time for older data)");
    }
  }
  io::GnssStreamDecoder decoder(o);
  decoder.push(bytes);
  decoder.finish();

  std::vector<core::ObsEpoch> ubx_epochs;
  std::vector<core::ObsEpoch> rtcm_epochs;
  while (auto e = decoder.pop_ubx_epoch()) ubx_epochs.push_back(std::move(*e));
  while (auto e = decoder.pop_rtcm3_epoch()) rtcm_epochs.push_back(std::move(*e));
  const bool use_ubx = format == io::StreamFormat::Ubx || (format == io::StreamFormat::Auto && !ubx_epochs.empty());
  if (use_ubx && !rtcm_epochs.empty()) {
    warnings.push_back("the input also holds " + std::to_string(rtcm_epochs.size()) +
                       " RTCM 3 observation epochs, not converted (--from rtcm3 converts them instead)");
  }
  // Receivers that clear the multiple message bit on every MSM (u-blox) split an epoch into one per constellation:
  // a file is written with one record per epoch time.
  merge_same_time(rtcm_epochs);
  std::vector<core::ObsEpoch>& epochs = use_ubx ? ubx_epochs : rtcm_epochs;
  summary.direction = use_ubx ? "ubx -> rinex" : "rtcm3 -> rinex";
  summary.epochs = static_cast<int>(epochs.size());
  summary.statistics = counts_line(decoder.stats());
  for (const std::string& p : decoder.problems()) warnings.push_back(config.input + ": " + p);
  for (const std::string& w : decoder.rtcm3().warnings()) warnings.push_back(config.input + ": " + w);
  for (const std::string& w : decoder.ubx().warnings()) warnings.push_back(config.input + ": " + w);
  if (epochs.empty() && decoder.navigation().kepler.empty() && decoder.navigation().glonass.empty()) {
    return Error{"no observations or ephemerides found (" + summary.statistics + ")", config.input, 0};
  }

  io::RinexObsHeader header;
  header.receiver.marker_name = config.marker;
  const auto& station = decoder.rtcm3().station();
  if (station && !use_ubx) {
    header.receiver.approx_position_E_m = station->arp_E_m;
    if (station->antenna_height_m) header.receiver.antenna_delta_hen_m.x() = *station->antenna_height_m;
    if (header.receiver.marker_name.empty())
      header.receiver.marker_name = "RTCM " + std::to_string(station->station_id);
  }
  if (const auto& antenna = decoder.rtcm3().antenna(); antenna && !use_ubx) {
    header.receiver.antenna_type = antenna->antenna_descriptor;
    header.receiver.receiver_type = antenna->receiver_type;
  }
  if (header.receiver.marker_name.empty()) {
    header.receiver.marker_name = std::filesystem::path(sibling(config.input, "")).stem().string();
  }
  header.receiver.glonass_slot_channels =
      use_ubx ? decoder.ubx().glonass_channels() : decoder.rtcm3().glonass_channels();
  const core::NavigationData nav = decoder.navigation();
  for (const core::GlonassEphemeris& g : nav.glonass) {
    bool known = false;
    for (const auto& sc : header.receiver.glonass_slot_channels) known = known || sc.first == g.sat.prn;
    if (!known) header.receiver.glonass_slot_channels.emplace_back(g.sat.prn, g.frequency_channel);
  }
  std::sort(header.receiver.glonass_slot_channels.begin(), header.receiver.glonass_slot_channels.end());

  const std::string obs_out = config.obs_out.empty() ? sibling(config.input, ".obs") : config.obs_out;
  const std::string nav_out = config.nav_out.empty() ? sibling(config.input, ".nav") : config.nav_out;
  if (!epochs.empty()) {
    if (Status s = io::write_rinex_obs(obs_out, header, epochs); !s.ok()) return s.error();
    summary.written.push_back(obs_out);
  }
  summary.ephemerides = static_cast<int>(nav.kepler.size() + nav.glonass.size());
  if (summary.ephemerides > 0) {
    if (Status s = io::write_rinex_nav(nav_out, nav); !s.ok()) return s.error();
    summary.written.push_back(nav_out);
  }
  summary.warnings = std::move(warnings);
  return summary;
}

Result<ConvertSummary> rinex_to_rtcm(const ConvertConfig& config, std::vector<std::string> warnings) {
  ConvertSummary summary;
  summary.direction = "rinex -> rtcm3";
  auto obs = io::read_rinex_obs(config.input);
  if (!obs) return obs.error();
  for (const std::string& w : obs->warnings) warnings.push_back(w);
  core::NavigationData nav;
  for (const std::string& path : config.nav) {
    auto file = io::read_rinex_nav(path);
    if (!file) return file.error();
    nav.merge(file->nav);
    for (const std::string& w : file->warnings) warnings.push_back(w);
  }
  io::Rtcm3StationStreamOptions o;
  o.encoder.station_id = config.station_id;
  o.encoder.msm_type = config.msm;
  o.encoder.glonass_channels = obs->header.receiver.glonass_slot_channels;
  o.station_interval_s = config.station_interval_s;
  o.ephemeris_interval_s = config.ephemeris_interval_s;
  io::Rtcm3StationStream stream(o);
  stream.add_navigation(nav);
  const std::optional<Eigen::Vector3d> position =
      config.position_E_m ? config.position_E_m : obs->header.receiver.approx_position_E_m;
  if (position) {
    io::rtcm3::StationPosition station;
    station.arp_E_m = *position;
    stream.set_station(station);
  } else {
    warnings.emplace_back("no station position (header APPROX POSITION XYZ is zero, no --position): no 1005 sent");
  }
  const std::string out_path = config.rtcm_out.empty() ? sibling(config.input, ".rtcm3") : config.rtcm_out;
  std::ofstream out(out_path, std::ios::binary);
  if (!out) return Error{"cannot write file", out_path, 0};
  for (const core::ObsEpoch& epoch : obs->epochs) {
    auto frames = stream.epoch(epoch);
    if (!frames) return Error{frames.error().message, config.input, 0};
    for (const io::Rtcm3Frame& f : *frames) {
      out.write(reinterpret_cast<const char*>(f.bytes.data()), static_cast<std::streamsize>(f.bytes.size()));
      ++summary.messages;
    }
    ++summary.epochs;
  }
  out.close();
  if (!out) return Error{"write failed", out_path, 0};
  summary.written.push_back(out_path);
  const io::Rtcm3StationStreamReport& r = stream.report();
  summary.ephemerides = r.ephemeris_messages;
  char text[320];
  std::snprintf(text, sizeof text,
                "%d MSM%d messages (%d cells), %d station and %d ephemeris messages; left out: %d signals without an "
                "RTCM id, %d satellites without pseudorange, %d GLONASS phases without channel, %d values out of "
                "range; %d arcs restarted",
                r.observations.messages, config.msm, r.observations.cells, r.station_messages, r.ephemeris_messages,
                r.observations.unsupported_signals, r.observations.dropped_satellites,
                r.observations.phase_without_channel, r.observations.invalid_values, r.observations.arc_restarts);
  summary.statistics = text;
  for (const std::string& w : r.warnings) warnings.push_back(w);
  summary.warnings = std::move(warnings);
  return summary;
}

/// A solution file's epochs as map tracks (KML, GPX).
Result<ConvertSummary> pos_to_tracks(const ConvertConfig& config) {
  auto solutions = io::read_pos_file(config.input);
  if (!solutions) return solutions.error();
  eval::MapTracks tracks;
  tracks.tracks.push_back({std::filesystem::path(config.input).stem().string(), std::move(*solutions)});
  ConvertSummary summary;
  summary.epochs = static_cast<int>(tracks.tracks.front().solutions.size());
  std::string kml = config.kml;
  if (kml.empty() && config.gpx.empty()) kml = std::filesystem::path(config.input).replace_extension(".kml").string();
  if (!kml.empty()) {
    if (Status s = eval::write_kml(kml, tracks); !s) return s.error();
    summary.written.push_back(kml);
  }
  if (!config.gpx.empty()) {
    if (Status s = eval::write_gpx(config.gpx, tracks); !s) {
      Error e = s.error();
      if (!kml.empty()) e.message += " (written before it and kept: " + kml + ")";
      return e;
    }
    summary.written.push_back(config.gpx);
  }
  summary.direction = kml.empty() ? "pos -> gpx" : (config.gpx.empty() ? "pos -> kml" : "pos -> kml, gpx");
  summary.statistics = std::to_string(summary.epochs) + " solutions";
  return summary;
}

}  // namespace

std::string ConvertConfig::validate() const {
  if (input.empty()) return "an input file is required";
  if (from != "auto" && from != "rtcm3" && from != "ubx" && from != "rinex" && from != "pos") {
    return "--from must be auto, rtcm3, ubx, rinex or pos, not '" + from + "'";
  }
  if ((!kml.empty() || !gpx.empty()) && from != "auto" && from != "pos") {
    return "--kml and --gpx take a solution file (.pos), not --from " + from;
  }
  if ((from == "pos" || !kml.empty() || !gpx.empty()) && (input == "-" || input.find("://") != std::string::npos)) {
    return "a solution input (.pos) must be a file";
  }
  if (from == "rinex" && (input == "-" || input.find("://") != std::string::npos)) return "RINEX input must be a file";
  if (!(duration_s >= 0.0)) return "duration must be >= 0 s";
  if (!(idle_timeout_s > 0.0)) return "idle timeout must be > 0 s";
  if (ntrip_version != 1 && ntrip_version != 2) return "NTRIP version must be 1 or 2";
  if (station_id < 0 || station_id > 4095) return "station id must be within 0-4095";
  if (msm < 4 || msm > 7) return "MSM type must be 4, 5, 6 or 7";
  if (!(station_interval_s >= 0.0)) return "station interval must be >= 0 s";
  if (!(ephemeris_interval_s >= 0.0)) return "ephemeris interval must be >= 0 s";
  return {};
}

Result<ConvertSummary> run_convert(const ConvertConfig& config) {
  if (const std::string e = config.validate(); !e.empty()) return Error{e};
  std::vector<std::string> warnings;
  if (config.from == "pos" || !config.kml.empty() || !config.gpx.empty()) return pos_to_tracks(config);
  if (config.from == "rinex") return rinex_to_rtcm(config, warnings);
  auto bytes = read_input(config, warnings);
  if (!bytes) return bytes.error();
  if (config.from == "auto" && looks_like_rinex(*bytes)) return rinex_to_rtcm(config, warnings);
  const auto format = io::parse_stream_format(config.from);
  return binary_to_rinex(config, *bytes, format.value_or(io::StreamFormat::Auto), std::move(warnings));
}

}  // namespace canyon::commands
