// EpochGeometryBuilder owns the cycle-slip detectors of both receivers: it scans exactly the epochs the engine goes
// on with, and an engine fed geometries built ahead gives the same epochs as one that builds its own. A base epoch
// that serves several rover epochs keeps its zero differences until the base position or the ephemerides change.

#include "canyon/rtk/epoch_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "canyon/gnss/ephemeris.hpp"
#include "canyon/io/rinex_nav.hpp"
#include "canyon/io/rinex_obs.hpp"
#include "canyon/rtk/engine.hpp"

namespace canyon::rtk {
namespace {

namespace fs = std::filesystem;

const fs::path kDir = fs::path(CANYON_SHARED_DATA_DIR) / "cssrlib-kinematic-doy265";
const Eigen::Vector3d kBase_E_m{-3959400.631, 3385704.533, 3667523.111};  // the dataset's README

struct Dataset {
  io::RinexObsFile rover;
  io::RinexObsFile base;
  core::NavigationData nav;
};

std::optional<Dataset> load() {
  auto rover = io::read_rinex_obs((kDir / "SEPT265G.21O").string());
  auto base = io::read_rinex_obs((kDir / "3034265G.21O").string());
  auto nav = io::read_rinex_nav((kDir / "SEPT2650.21P").string());
  if (!rover || !base || !nav) {
    ADD_FAILURE() << "cannot read the dataset in " << kDir;
    return std::nullopt;
  }
  return Dataset{std::move(*rover), std::move(*base), std::move(nav->nav)};
}

/// The latest base epoch tagged at most 10 ms after the rover's (the dataset's tags are 5 ms apart), or nullptr.
const core::ObsEpoch* base_for(const io::RinexObsFile& base, const core::ObsEpoch& rover) {
  const core::ObsEpoch* out = nullptr;
  for (const core::ObsEpoch& b : base.epochs) {
    if (b.time - rover.time > 0.01) break;
    out = &b;
  }
  return out;
}

#define SKIP_WITHOUT_DATA() \
  if (!fs::exists(kDir)) GTEST_SKIP() << "shared dataset not present: " << kDir

TEST(EpochGeometry, BuiltAheadGivesTheEpochsOfTheEnginesOwnGeometry) {
  SKIP_WITHOUT_DATA();
  const auto data = load();
  ASSERT_TRUE(data);
  const gnss::EphemerisStore eph(data->nav);
  RtkOptions options;
  options.ar_mode = ArMode::Continuous;
  RtkEngine own(options, eph, kBase_E_m);
  RtkEngine fed(options, eph, kBase_E_m);
  EpochGeometryBuilder builder(fed.geometry_options(), eph, kBase_E_m);
  // The scan against detectors fed here with the scanned epochs (the base's only when it is a new epoch).
  CycleSlipDetector rover_slips(options.slips);
  CycleSlipDetector base_slips(options.slips);
  std::optional<core::GpsTime> last_base_time;
  int rover_slip_events = 0;
  int fixed = 0;
  for (const core::ObsEpoch& rover : data->rover.epochs) {
    const core::ObsEpoch* base = base_for(data->base, rover);
    auto expected = own.process(rover, base);
    EpochGeometry geometry = builder.build(rover, base);
    if (geometry.slips) {
      std::vector<SlipEvent> events = rover_slips.update(geometry.rover_obs);
      rover_slip_events += static_cast<int>(events.size());
      if (!last_base_time || std::abs(geometry.base_obs.time - *last_base_time) > 1e-6) {
        const std::vector<SlipEvent> base_events = base_slips.update(geometry.base_obs);
        events.insert(events.end(), base_events.begin(), base_events.end());
        last_base_time = geometry.base_obs.time;
      }
      ASSERT_EQ(events.size(), geometry.slips->events.size()) << rover.time.tow_s;
      for (std::size_t k = 0; k < events.size(); ++k) {
        EXPECT_EQ(events[k].sat, geometry.slips->events[k].sat);
        EXPECT_EQ(events[k].frequency, geometry.slips->events[k].frequency);
        EXPECT_EQ(events[k].cause, geometry.slips->events[k].cause);
      }
      for (const SignalObservable& s : geometry.rover_obs.signals) {
        EXPECT_EQ(rover_slips.half_cycle_unresolved(s.sat, s.frequency) ||
                      base_slips.half_cycle_unresolved(s.sat, s.frequency),
                  geometry.slips->half_cycle(s.sat, s.frequency));
      }
    }
    auto more = fed.predict(rover, base, nullptr, &geometry);
    ASSERT_EQ(static_cast<bool>(expected), static_cast<bool>(more)) << rover.time.tow_s;
    if (!more) continue;
    if (*more && fed.update()) fed.resolve();
    const RtkEpoch got = fed.take_epoch();
    ASSERT_EQ(expected->solution.status, got.solution.status) << rover.time.tow_s;
    EXPECT_EQ(expected->solution.p_E_m, got.solution.p_E_m) << rover.time.tow_s;
    EXPECT_EQ(expected->num_fixed_ambiguities, got.num_fixed_ambiguities) << rover.time.tow_s;
    if (got.solution.status == core::SolutionStatus::Fixed) ++fixed;
  }
  EXPECT_GT(rover_slip_events, 0) << "the rover file has slips: the scan must see them";
  EXPECT_GT(fixed, 0);
}

TEST(EpochGeometry, ScansOnlyTheEpochsThePredictionGoesOnWith) {
  SKIP_WITHOUT_DATA();
  const auto data = load();
  ASSERT_TRUE(data);
  const gnss::EphemerisStore eph(data->nav);
  const RtkEngine engine(RtkOptions{}, eph, kBase_E_m);
  EpochGeometryBuilder builder(engine.geometry_options(), eph, kBase_E_m);
  const core::ObsEpoch& first = data->rover.epochs.front();
  const core::ObsEpoch& later = data->rover.epochs.back();
  ASSERT_GT(later.time - first.time, RtkOptions{}.max_age_s);

  EXPECT_FALSE(builder.build(first, nullptr).slips) << "no base";
  EXPECT_FALSE(builder.build(later, base_for(data->base, first)).slips) << "a base older than max_age_s";
  const EpochGeometry with_base = builder.build(first, base_for(data->base, first));
  ASSERT_TRUE(with_base.spp);
  EXPECT_TRUE(with_base.slips);
  core::ObsEpoch without_signals = first;
  without_signals.sats.clear();
  const EpochGeometry no_spp = builder.build(without_signals, base_for(data->base, first));
  EXPECT_FALSE(no_spp.spp);
  EXPECT_FALSE(no_spp.slips) << "no single-point solution, not aided";
  EXPECT_TRUE(builder.build(without_signals, base_for(data->base, first), true).slips) << "aided";
}

TEST(EpochGeometry, AGeometryWithoutItsSlipScanIsAnError) {
  SKIP_WITHOUT_DATA();
  const auto data = load();
  ASSERT_TRUE(data);
  const gnss::EphemerisStore eph(data->nav);
  RtkEngine engine(RtkOptions{}, eph, kBase_E_m);
  EpochGeometryBuilder::Options other = engine.geometry_options();
  other.max_base_age_s = -1.0;  // scans nothing
  EpochGeometryBuilder builder(other, eph, kBase_E_m);
  const core::ObsEpoch& rover = data->rover.epochs.front();
  const core::ObsEpoch* base = base_for(data->base, rover);
  EpochGeometry geometry = builder.build(rover, base);
  const auto result = engine.predict(rover, base, nullptr, &geometry);
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("cycle-slip scan"), std::string::npos) << result.error().message;
}

/// The builder's base side equals that of a builder that never saw an epoch before (nothing cached).
void expect_base_side_as_built_alone(const EpochGeometry& got, const EpochGeometryBuilder::Options& options,
                                     const gnss::EphemerisStore& eph, const Eigen::Vector3d& p_E_base_m,
                                     const core::ObsEpoch& rover, const core::ObsEpoch* base) {
  EpochGeometryBuilder alone(options, eph, p_E_base_m);
  const EpochGeometry expected = alone.build(rover, base);
  ASSERT_EQ(expected.base_obs.signals.size(), got.base_obs.signals.size());
  ASSERT_EQ(expected.base_models.size(), got.base_models.size());
  for (std::size_t k = 0; k < got.base_models.size(); ++k) {
    EXPECT_EQ(expected.base_models[k].first, got.base_models[k].first);
    EXPECT_EQ(expected.base_models[k].second.valid, got.base_models[k].second.valid);
    EXPECT_EQ(expected.base_models[k].second.model_m, got.base_models[k].second.model_m);
    EXPECT_EQ(expected.base_models[k].second.los_E, got.base_models[k].second.los_E);
  }
}

TEST(EpochGeometry, ABaseEpochServingSeveralRoverEpochsKeepsItsModelsUntilThePositionOrEphemeridesChange) {
  SKIP_WITHOUT_DATA();
  const auto data = load();
  ASSERT_TRUE(data);
  const core::ObsEpoch* base = base_for(data->base, data->rover.epochs.front());
  ASSERT_NE(base, nullptr);
  // A store without the ephemerides of the base's first GPS satellite, which arrive later (add()).
  const auto gps = std::find_if(base->sats.begin(), base->sats.end(),
                                [](const core::SatelliteObs& s) { return s.sat.system == core::Constellation::Gps; });
  ASSERT_NE(gps, base->sats.end());
  const core::SatelliteId missing = gps->sat;
  core::NavigationData partial = data->nav;
  std::erase_if(partial.kepler, [&](const core::KeplerEphemeris& e) { return e.sat == missing; });
  gnss::EphemerisStore eph(partial);
  const RtkEngine engine(RtkOptions{}, eph, kBase_E_m);
  const EpochGeometryBuilder::Options options = engine.geometry_options();
  EpochGeometryBuilder builder(options, eph, kBase_E_m);
  const auto model_of = [&](const EpochGeometry& g) { return g.base_model(missing); };
  for (std::size_t k = 0; k < 3; ++k) {  // one base epoch, three rover epochs
    const EpochGeometry g = builder.build(data->rover.epochs[k], base);
    expect_base_side_as_built_alone(g, options, eph, kBase_E_m, data->rover.epochs[k], base);
    EXPECT_FALSE(model_of(g).valid) << "no ephemeris for " << missing.to_string() << " yet";
  }
  const Eigen::Vector3d moved = kBase_E_m + Eigen::Vector3d(10.0, -5.0, 3.0);
  builder.set_base_position(moved);
  const EpochGeometry after_move = builder.build(data->rover.epochs[3], base);
  expect_base_side_as_built_alone(after_move, options, eph, moved, data->rover.epochs[3], base);
  ASSERT_GT(eph.add(data->nav), 0);
  const EpochGeometry after_add = builder.build(data->rover.epochs[4], base);
  expect_base_side_as_built_alone(after_add, options, eph, moved, data->rover.epochs[4], base);
  EXPECT_TRUE(model_of(after_add).valid) << "the new ephemerides reach the base epoch already seen";
}

}  // namespace
}  // namespace canyon::rtk
