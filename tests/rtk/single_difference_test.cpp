// Single differences (rtk/single_difference.hpp): the zero-difference weight models, and an epoch of a simulated
// open-sky scenario differenced at the true position: ordered by satellite and frequency, above the mask, code and
// phase weights in the configured ratio, small residuals (the models cancel), ionosphere scales per frequency.

#include "canyon/rtk/single_difference.hpp"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <unistd.h>

#include "canyon/config/scenario_config.hpp"
#include "canyon/core/constants.hpp"
#include "canyon/sim/simulator.hpp"

namespace canyon::rtk {
namespace {

namespace fs = std::filesystem;

TEST(SingleDifference, WeightModels) {
  RtkOptions o;
  o.phase_sigma_m = 0.003;
  o.phase_sigma_el_m = 0.004;
  const double el = 30.0 * core::kDegToRad;
  EXPECT_DOUBLE_EQ(zero_diff_phase_variance(o, el, 45.0), 0.003 * 0.003 + 0.004 * 0.004 / 0.25);
  EXPECT_DOUBLE_EQ(zero_diff_phase_variance(o, -1.0, core::kNoValue),
                   0.003 * 0.003 + 0.004 * 0.004 / (0.05 * 0.05));  // sin(el) held at 0.05
  o.snr_weighting = true;
  o.snr_reference_dbhz = 45.0;
  EXPECT_DOUBLE_EQ(zero_diff_phase_variance(o, el, 35.0), 0.003 * 0.003 + 0.004 * 0.004 * 10.0);
  EXPECT_DOUBLE_EQ(zero_diff_phase_variance(o, el, core::kNoValue), 0.003 * 0.003 + 0.004 * 0.004 / 0.25);
}

TEST(SingleDifference, AnEpochDifferencedAtTheTruth) {
  auto scenario = config::load_scenario((fs::path(CANYON_SOURCE_DIR) / "config/scenarios/open-sky.yaml").string());
  ASSERT_TRUE(scenario.ok()) << scenario.error().to_string();
  scenario->duration_s = 5.0;
  const fs::path dir = fs::temp_directory_path() / ("canyon_single_difference_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto sim = sim::simulate(*scenario, (dir / "nav.rnx").string());
  fs::remove_all(dir);
  ASSERT_TRUE(sim.ok()) << sim.error().to_string();
  const gnss::EphemerisStore eph(sim->nav);
  RtkOptions options;
  options.observables.num_frequencies = 2;
  const EpochGeometryBuilder::Options geometry_options{options.spp, options.observables, true, options.slips, 30.0};
  const core::ObsEpoch& rover = sim->rover.epochs[2];
  const core::ObsEpoch* base = nullptr;
  for (const core::ObsEpoch& b : sim->base.epochs) {
    if (b.time - rover.time <= 0.05) base = &b;
  }
  ASSERT_NE(base, nullptr);
  const auto form = [&](const RtkOptions& o, bool iono) {
    EpochGeometryBuilder builder(geometry_options, eph, sim->base_p_E_m);
    EpochGeometry geometry = builder.build(rover, base);
    return form_single_differences(geometry, sim->truth[2].p_E_m, o, eph, iono);
  };
  const std::vector<SingleDiff> sds = form(options, true);
  ASSERT_GT(sds.size(), 10U);
  for (std::size_t i = 0; i < sds.size(); ++i) {
    const SingleDiff& sd = sds[i];
    if (i > 0) {
      EXPECT_LT(std::pair(sds[i - 1].sat, sds[i - 1].frequency), std::pair(sd.sat, sd.frequency));
    }
    EXPECT_GE(sd.elevation_rad, options.elevation_mask_rad);
    EXPECT_NEAR(sd.los_E.norm(), 1.0, 1e-12);
    EXPECT_DOUBLE_EQ(sd.code_variance_m2, sd.phase_variance_m2 * options.code_phase_ratio * options.code_phase_ratio);
    EXPECT_EQ(sd.group, static_cast<int>(sd.sat.system) * kMaxFrequencies + sd.frequency);
    EXPECT_EQ(sd.ambiguity, -1);  // indices are the bookkeeping's (ambiguity_states.hpp)
    ASSERT_TRUE(core::has_value(sd.code_m));
    // The models cancel to the receivers' clock difference (common to every SD, gone in the double differences)
    // and the differential errors.
    EXPECT_LT(std::abs(sd.code_m - sds[0].code_m), 30.0) << sd.sat.to_string();
    const double scale = std::pow(sd.wavelength_m / first_wavelength_m(eph, sd.sat), 2);
    EXPECT_DOUBLE_EQ(sd.iono_scale, scale);
    if (sd.frequency == 0) {
      EXPECT_DOUBLE_EQ(sd.iono_scale, 1.0);
    }
  }
  RtkOptions high_mask = options;
  high_mask.elevation_mask_rad = 45.0 * core::kDegToRad;
  EXPECT_LT(form(high_mask, false).size(), sds.size());
}

}  // namespace
}  // namespace canyon::rtk
