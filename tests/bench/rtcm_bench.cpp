// Speed of the RTCM 3 codec.
//
// BM_DecodeMsm7Stream: a byte stream of MSM7 epochs (GPS, GLONASS, Galileo, BeiDou; 40 satellites x 2 signals,
//   split per constellation as a receiver sends them) through StreamFramer (preamble, length, CRC-24Q) and
//   Rtcm3Decoder into core::ObsEpoch: the whole receive path. bytes_per_second is the throughput.
// BM_DecodeMsm7Payload: decode_msm alone on one message payload (no framing, no epoch assembly).
// BM_EncodeEpoch/N: Rtcm3Encoder::encode_epoch of one epoch of N satellites x 2 signals into MSM7 frames (lock
//   times, phase arcs, CRC included).
//
// Reproduce (Release, 2 cores, Debian 12, g++ 12):
//   cmake --build build -j2 --target bench_rtcm
//   build/tests/bench/bench_rtcm --benchmark_repetitions=9 --benchmark_report_aggregates_only=true
// Results: see README.md, "Measured".

#include <cmath>
#include <vector>

#include <benchmark/benchmark.h>

#include "canyon/io/rtcm3.hpp"
#include "canyon/io/rtcm3_codec.hpp"
#include "canyon/io/stream_framer.hpp"

namespace {

using canyon::core::Constellation;
using canyon::core::GpsTime;
using canyon::core::ObsEpoch;
using canyon::core::SatelliteId;
using canyon::core::SatelliteObs;
using canyon::core::SignalCode;
using canyon::core::SignalObs;

/// An epoch of `nsat` satellites with two signals each, spread over four constellations.
ObsEpoch epoch_of(int nsat, double t_s) {
  ObsEpoch e;
  e.time = GpsTime{2176, 282600.0 + t_s};
  struct Plan {
    Constellation system;
    SignalCode a, b;
    int count;
  };
  const int per = nsat / 4;
  const Plan plans[] = {{Constellation::Gps, {'1', 'C'}, {'2', 'W'}, nsat - 3 * per},
                        {Constellation::Glonass, {'1', 'C'}, {'2', 'C'}, per},
                        {Constellation::Galileo, {'1', 'C'}, {'7', 'Q'}, per},
                        {Constellation::BeiDou, {'2', 'I'}, {'7', 'I'}, per}};
  for (const Plan& p : plans) {
    for (int k = 1; k <= p.count; ++k) {
      SatelliteObs so;
      so.sat = SatelliteId{p.system, static_cast<std::uint8_t>(k)};
      const double range = 2.1e7 + 1.5e5 * k + 500.0 * t_s * std::sin(k);
      for (const SignalCode code : {p.a, p.b}) {
        const int channel = p.system == Constellation::Glonass ? (k % 14) - 7 : canyon::core::kNoGlonassChannel;
        const double lambda = *canyon::core::wavelength_m(p.system, code, channel);
        SignalObs s;
        s.code = code;
        s.pseudorange_m = range + (code.band - '0');
        s.carrier_phase_cyc = range / lambda + 1000.0 * k;
        s.doppler_hz = -500.0 * std::sin(k) / lambda;
        s.snr_dbhz = 45.0;
        so.signals.push_back(s);
      }
      e.sats.push_back(so);
    }
  }
  return e;
}

canyon::io::Rtcm3EncoderOptions encoder_options() {
  canyon::io::Rtcm3EncoderOptions o;
  o.station_id = 1;
  o.msm_type = 7;
  for (int slot = 1; slot <= 24; ++slot) o.glonass_channels.emplace_back(slot, (slot % 14) - 7);
  return o;
}

std::vector<std::uint8_t> msm7_stream(int epochs) {
  canyon::io::Rtcm3Encoder encoder(encoder_options());
  std::vector<std::uint8_t> bytes;
  for (int k = 0; k < epochs; ++k) {
    std::vector<canyon::io::Rtcm3Frame> frames;
    (void)encoder.encode_epoch(epoch_of(40, k), frames);
    for (const auto& f : frames) bytes.insert(bytes.end(), f.bytes.begin(), f.bytes.end());
  }
  return bytes;
}

void BM_DecodeMsm7Stream(benchmark::State& state) {
  const std::vector<std::uint8_t> stream = msm7_stream(100);
  std::int64_t epochs = 0;
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    canyon::io::Rtcm3DecoderOptions o;
    o.reference_time = GpsTime{2176, 282600.0};
    canyon::io::Rtcm3Decoder decoder(o);
    canyon::io::StreamFramer framer(canyon::io::StreamFramer::Options{true, false, false});
    // Reads of 4 KiB, as from a socket.
    for (std::size_t pos = 0; pos < stream.size(); pos += 4096) {
      framer.push({stream.data() + pos, std::min<std::size_t>(4096, stream.size() - pos)});
      while (auto p = framer.next()) {
        auto m = decoder.decode(p->payload());
        benchmark::DoNotOptimize(m);
        while (auto e = decoder.pop_epoch()) {
          benchmark::DoNotOptimize(e->sats.data());
          ++epochs;
        }
      }
    }
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(stream.size()));
  state.counters["epochs"] = benchmark::Counter(static_cast<double>(epochs), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DecodeMsm7Stream);

void BM_DecodeMsm7Payload(benchmark::State& state) {
  const std::vector<std::uint8_t> stream = msm7_stream(1);
  canyon::io::StreamFramer framer;
  framer.push(stream);
  const auto packet = framer.next();
  const std::vector<std::uint8_t> payload(packet->payload().begin(), packet->payload().end());
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    auto m = canyon::io::rtcm3::decode_msm(payload);
    benchmark::DoNotOptimize(m);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(payload.size()));
}
BENCHMARK(BM_DecodeMsm7Payload);

void BM_EncodeEpoch(benchmark::State& state) {
  const int nsat = static_cast<int>(state.range(0));
  std::vector<ObsEpoch> epochs;
  epochs.reserve(64);
  for (int k = 0; k < 64; ++k) epochs.push_back(epoch_of(nsat, k));
  canyon::io::Rtcm3Encoder encoder(encoder_options());
  std::vector<canyon::io::Rtcm3Frame> frames;
  std::size_t k = 0;
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    frames.clear();
    auto r = encoder.encode_epoch(epochs[k++ % epochs.size()], frames);
    benchmark::DoNotOptimize(r);
    benchmark::DoNotOptimize(frames.data());
  }
}
BENCHMARK(BM_EncodeEpoch)->Arg(40)->Arg(64);

}  // namespace
