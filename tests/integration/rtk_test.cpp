// RTK end to end on the shared real and simulated datasets, against truth and against RTKLIB 2.4.3's own results
// shipped in each dataset's rtklib/ folder (same files, same settings). The figures asserted are those issue 3 asks
// for; the ones still open (QZSS never worse, m8p, speed) are reported by tests/bench/rtk_vs_rtklib.sh.

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "canyon/commands/process.hpp"
#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/eval/metrics.hpp"
#include "canyon/eval/truth.hpp"
#include "canyon/io/nmea.hpp"
#include "canyon/io/rinex_obs.hpp"

#include "test_support.hpp"

namespace canyon {
namespace {

namespace fs = std::filesystem;
using test::shared_data;

constexpr double kMaxStaticRmse3dM = 0.01;
constexpr double kMaxDistanceToRtklibFixM = 0.03;
constexpr double kWrongFixM = 0.10;

Eigen::Vector3d llh_deg(double lat, double lon, double h) {
  return core::geodetic_to_ecef({lat * core::kDegToRad, lon * core::kDegToRad, h});
}

struct RtkRun {
  commands::ProcessSummary summary;
  std::vector<core::Solution> solutions;
};

std::optional<RtkRun> run_rtk(const std::string& name, const std::string& rover, const std::string& base,
                              const std::vector<std::string>& nav, const Eigen::Vector3d& p_E_base,
                              const std::function<void(config::ProcessConfig&)>& adjust = {}) {
  config::ProcessConfig c;
  c.mode = config::ProcessMode::Rtk;
  c.rover_obs = (shared_data() / rover).string();
  c.base_obs = (shared_data() / base).string();
  for (const auto& n : nav) c.nav.push_back((shared_data() / n).string());
  c.base_position_E_m = p_E_base;
  // A folder per test: ctest runs the tests in parallel, and two of them use the same name.
  const std::string test_name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  c.out = (test::temp_dir("rtk_" + test_name) / (name + ".pos")).string();
  if (adjust) adjust(c);
  auto summary = commands::run_process(c);
  EXPECT_TRUE(summary.ok()) << summary.error().to_string();
  if (!summary) return std::nullopt;
  auto sols = io::read_pos_file(c.out);
  EXPECT_TRUE(sols.ok());
  if (!sols) return std::nullopt;
  return RtkRun{*summary, std::move(*sols)};
}

void expect_static_fixed(const RtkRun& run, const Eigen::Vector3d& truth, const std::string& name) {
  eval::EvalOptions options;
  options.wrong_fix_threshold_m = kWrongFixM;
  auto stats = eval::evaluate(run.solutions, eval::Truth::constant(truth), options);
  ASSERT_TRUE(stats.ok());
  std::cout << "[ RTK      ] " << name << ": " << stats->fixed().epochs << "/" << run.summary.epochs
            << " fixed, 3D RMSE " << stats->overall.rmse_3d_m << " m, first fix after "
            << stats->time_to_first_fix_s.value_or(-1) << " s\n";
  EXPECT_EQ(stats->fixed().epochs, run.summary.epochs);
  ASSERT_TRUE(stats->time_to_first_fix_s.has_value());
  EXPECT_LE(*stats->time_to_first_fix_s, 5.0);
  EXPECT_LE(stats->overall.rmse_3d_m, kMaxStaticRmse3dM);
  EXPECT_EQ(stats->wrong_fixes, 0);
}

#define REQUIRE_DATA(path) \
  if (!fs::exists(shared_data() / (path))) GTEST_SKIP() << "shared dataset not present: " << shared_data() / (path)

TEST(RtkRealData, CssrlibStaticEveryEpochFixedWithinOneCentimetre) {
  REQUIRE_DATA("cssrlib-static-doy078");
  const Eigen::Vector3d base(-3959400.631, 3385704.533, 3667523.111);
  const Eigen::Vector3d truth(-3962108.673, 3381309.574, 3668678.638);
  for (const auto mode : {rtk::ArMode::Continuous, rtk::ArMode::Instantaneous}) {
    auto run = run_rtk("cssrlib_static", "cssrlib-static-doy078/SEPT078M1.21O", "cssrlib-static-doy078/3034078M1.21O",
                       {"cssrlib-static-doy078/SEPT078M.21P"}, base, [&](config::ProcessConfig& c) {
                         c.rtk.ar_mode = mode;
                         c.rtk.observables.use_glonass = c.rtk.observables.use_beidou = false;
                       });
    ASSERT_TRUE(run.has_value());
    expect_static_fixed(*run, truth, std::string("cssrlib-static ") + rtk::ar_mode_name(mode));
  }
}

TEST(RtkRealData, MatrtklibStaticEveryEpochFixedWithinOneCentimetre) {
  REQUIRE_DATA("matrtklib-static");
  const Eigen::Vector3d base = llh_deg(35.134707705, 136.977577939, 104.853);
  const Eigen::Vector3d truth = llh_deg(35.13469901, 136.97757549, 104.8626);
  for (const auto mode : {rtk::ArMode::Continuous, rtk::ArMode::Instantaneous, rtk::ArMode::FixAndHold}) {
    auto run = run_rtk("matrtklib", "matrtklib-static/rover.obs", "matrtklib-static/base.obs",
                       {"matrtklib-static/base.nav"}, base, [&](config::ProcessConfig& c) { c.rtk.ar_mode = mode; });
    ASSERT_TRUE(run.has_value());
    expect_static_fixed(*run, truth, std::string("matrtklib ") + rtk::ar_mode_name(mode));
  }
}

/// GLONASS AR on two receivers of one type (matrtklib: two Septentrio mosaic-X5, GPS + GLONASS + Galileo + BeiDou +
/// QZSS): the inter-frequency biases cancel, GLONASS ambiguities are fixed with the others, no warning. Receivers of
/// different types (cssrlib: Septentrio rover, Trimble base) get a warning.
TEST(RtkRealData, GlonassArOnIdenticalReceiversAndWarningOtherwise) {
  REQUIRE_DATA("matrtklib-static");
  REQUIRE_DATA("cssrlib-static-doy078");
  const Eigen::Vector3d base = llh_deg(35.134707705, 136.977577939, 104.853);
  const Eigen::Vector3d truth = llh_deg(35.13469901, 136.97757549, 104.8626);
  auto same = run_rtk("matrtklib-glonass", "matrtklib-static/rover.obs", "matrtklib-static/base.obs",
                      {"matrtklib-static/base.nav"}, base, [&](config::ProcessConfig& c) { c.rtk.glonass_ar = true; });
  ASSERT_TRUE(same.has_value());
  expect_static_fixed(*same, truth, "matrtklib glonass_ar on");
  const auto warns_glonass = [](const commands::ProcessSummary& s) {
    return std::any_of(s.warnings.begin(), s.warnings.end(),
                       [](const std::string& w) { return w.find("glonass_ar is on") != std::string::npos; });
  };
  EXPECT_FALSE(warns_glonass(same->summary));
  auto mixed = run_rtk("cssrlib-glonass", "cssrlib-static-doy078/SEPT078M1.21O", "cssrlib-static-doy078/3034078M1.21O",
                       {"cssrlib-static-doy078/SEPT078M.21P"}, Eigen::Vector3d(-3959400.631, 3385704.533, 3667523.111),
                       [&](config::ProcessConfig& c) { c.rtk.glonass_ar = true; });
  ASSERT_TRUE(mixed.has_value());
  EXPECT_TRUE(warns_glonass(mixed->summary));
}

struct InstinctCase {
  const char* variant;
  const char* rover;
  bool atmosphere;
};

TEST(RtkSimulator, InstinctBothVariantsBothRoversFixedWithinOneCentimetre) {
  REQUIRE_DATA("instinct-spirent-rtk-sim");
  const Eigen::Vector3d base(4157177.06580187, 671230.476590636, 4774767.03105544);
  const Eigen::Vector3d static_rover(4156857.1195929, 673209.028774142, 4774767.03105544);
  auto dynamic_truth =
      eval::read_spirent_pva_csv((shared_data() / "instinct-spirent-rtk-sim/Rover-dynamic_PVA_Spirent.csv").string());
  ASSERT_TRUE(dynamic_truth.ok()) << dynamic_truth.error().to_string();
  for (const InstinctCase& k : {InstinctCase{"iono-Klob_tropo-Saast", "dynamic", true},
                                InstinctCase{"iono-Klob_tropo-Saast", "static-2km-east", true},
                                InstinctCase{"iono-none_tropo-none", "dynamic", false},
                                InstinctCase{"iono-none_tropo-none", "static-2km-east", false}}) {
    const std::string dir = std::string("instinct-spirent-rtk-sim/") + k.variant + "/";
    auto run =
        run_rtk("instinct", dir + "Rover-" + k.rover + "_MO_Spirent.obs", dir + "Base-static_MO_Spirent.obs",
                {"instinct-spirent-rtk-sim/RINEX_GN_Spirent.23N", "instinct-spirent-rtk-sim/RINEX_EN_Spirent.23L"},
                base, [&](config::ProcessConfig& c) {
                  c.rtk.observables.use_glonass = c.rtk.observables.use_beidou = false;
                  c.rtk.troposphere_saastamoinen = k.atmosphere;  // the simulation's own models
                  c.spp.troposphere_saastamoinen = c.spp.ionosphere_klobuchar = k.atmosphere;
                });
    ASSERT_TRUE(run.has_value());
    const bool dynamic = std::string(k.rover) == "dynamic";
    eval::EvalOptions options;
    options.wrong_fix_threshold_m = kWrongFixM;
    auto stats = dynamic ? eval::evaluate(run->solutions, *dynamic_truth, options)
                         : eval::evaluate(run->solutions, eval::Truth::constant(static_rover), options);
    ASSERT_TRUE(stats.ok());
    std::cout << "[ RTK      ] instinct " << k.variant << " " << k.rover << ": " << stats->fixed().epochs << "/"
              << run->summary.epochs << " fixed, 3D RMSE " << stats->overall.rmse_3d_m << " m\n";
    EXPECT_GE(stats->fixed().epochs, run->summary.epochs * 99 / 100);
    EXPECT_LE(stats->overall.rmse_3d_m, kMaxStaticRmse3dM);
    EXPECT_EQ(stats->wrong_fixes, 0);
  }
}

TEST(RtkSimulator, InstinctDynamicRoverWithTheConstantAccelerationModel) {
  // dynamics: true (RTKLIB's "dynamics on"): position, velocity and acceleration carried by the motion model instead
  // of re-initialised from the single-point solution each epoch; the same accuracy on the moving rover.
  REQUIRE_DATA("instinct-spirent-rtk-sim");
  const Eigen::Vector3d base(4157177.06580187, 671230.476590636, 4774767.03105544);
  auto truth =
      eval::read_spirent_pva_csv((shared_data() / "instinct-spirent-rtk-sim/Rover-dynamic_PVA_Spirent.csv").string());
  ASSERT_TRUE(truth.ok()) << truth.error().to_string();
  const std::string dir = "instinct-spirent-rtk-sim/iono-Klob_tropo-Saast/";
  auto run = run_rtk("instinct_dynamics", dir + "Rover-dynamic_MO_Spirent.obs", dir + "Base-static_MO_Spirent.obs",
                     {"instinct-spirent-rtk-sim/RINEX_GN_Spirent.23N", "instinct-spirent-rtk-sim/RINEX_EN_Spirent.23L"},
                     base, [](config::ProcessConfig& c) {
                       c.rtk.observables.use_glonass = c.rtk.observables.use_beidou = false;
                       c.rtk.dynamics = true;
                     });
  ASSERT_TRUE(run.has_value());
  eval::EvalOptions options;
  options.wrong_fix_threshold_m = kWrongFixM;
  auto stats = eval::evaluate(run->solutions, *truth, options);
  ASSERT_TRUE(stats.ok());
  std::cout << "[ RTK      ] instinct dynamic, constant-acceleration model: " << stats->fixed().epochs << "/"
            << run->summary.epochs << " fixed, 3D RMSE " << stats->overall.rmse_3d_m << " m\n";
  EXPECT_GE(stats->fixed().epochs, run->summary.epochs * 99 / 100);
  EXPECT_LE(stats->overall.rmse_3d_m, kMaxStaticRmse3dM);
  EXPECT_EQ(stats->wrong_fixes, 0);
}

TEST(RtkSimulator, ExcludedSatellitesNeverReachTheSinglePointPrior) {
  // GPS only, the most observed satellites left out: the RTK engine's single-point prior is the one `spp:`
  // configures, exclusions included. With 4 left it has a position every epoch; with 3 left none can be formed, so
  // no epoch is solved (before, the prior came from SppOptions' defaults with every satellite: 601 solutions, 94 %
  // "fixed" on two double differences).
  REQUIRE_DATA("instinct-spirent-rtk-sim");
  const Eigen::Vector3d base(4157177.06580187, 671230.476590636, 4774767.03105544);
  const std::string dir = "instinct-spirent-rtk-sim/iono-Klob_tropo-Saast/";
  for (const int excluded : {4, 5}) {
    auto run =
        run_rtk("gps_excluded_" + std::to_string(excluded), dir + "Rover-dynamic_MO_Spirent.obs",
                dir + "Base-static_MO_Spirent.obs",
                {"instinct-spirent-rtk-sim/RINEX_GN_Spirent.23N", "instinct-spirent-rtk-sim/RINEX_EN_Spirent.23L"},
                base, [excluded](config::ProcessConfig& c) {
                  c.spp.use_glonass = c.spp.use_galileo = c.spp.use_beidou = c.spp.use_qzss = false;
                  c.rtk.observables.use_glonass = c.rtk.observables.use_galileo = false;
                  c.rtk.observables.use_beidou = c.rtk.observables.use_qzss = false;
                  c.exclude_most_observed = excluded;
                });
    ASSERT_TRUE(run.has_value());
    std::cout << "[ RTK      ] instinct dynamic, GPS, " << excluded
              << " most observed left out: " << run->summary.solved << "/" << run->summary.epochs << " solved\n";
    EXPECT_EQ(run->summary.epochs, 601);
    if (excluded == 4) {
      EXPECT_GE(run->summary.solved, 570);  // 579: a few epochs have 3 of the 4 above the mask
    } else {
      EXPECT_EQ(run->summary.solved, 0);
    }
  }
}

/// cssrlib-kinematic-doy265: fix rate at least RTKLIB's in the same AR mode, fixed positions within 3 cm of
/// RTKLIB's where both are fixed (RTKLIB's results are the ones shipped with the dataset).
TEST(RtkRealData, CssrlibKinematicFixRateAtLeastRtklibs) {
  REQUIRE_DATA("cssrlib-kinematic-doy265");
  const Eigen::Vector3d base(-3959400.631, 3385704.533, 3667523.111);
  struct Case {
    rtk::ArMode mode;
    const char* rtklib_pos;
  };
  std::vector<std::string> unexplained;  // modes with epochs beyond kMaxDistanceToRtklibFixM and no RTKLIB to run
  for (const Case& k : {Case{rtk::ArMode::Continuous, "rtk_kinematic.pos"},
                        Case{rtk::ArMode::Instantaneous, "rtk_kinematic_inst.pos"}}) {
    auto run = run_rtk("kinematic", "cssrlib-kinematic-doy265/SEPT265G.21O", "cssrlib-kinematic-doy265/3034265G.21O",
                       {"cssrlib-kinematic-doy265/SEPT2650.21P"}, base, [&](config::ProcessConfig& c) {
                         c.rtk.ar_mode = k.mode;
                         c.rtk.observables.use_glonass = c.rtk.observables.use_beidou = false;
                         c.rtk.observables.use_qzss = false;  // RTKLIB's reference runs are GPS + Galileo
                       });
    ASSERT_TRUE(run.has_value());
    auto rtklib = io::read_pos_file((shared_data() / "cssrlib-kinematic-doy265/rtklib" / k.rtklib_pos).string());
    ASSERT_TRUE(rtklib.ok());
    auto ours = eval::evaluate(run->solutions, nullptr);
    auto theirs = eval::evaluate(*rtklib, nullptr);
    auto agreement = eval::compare(run->solutions, *rtklib);
    ASSERT_TRUE(ours.ok() && theirs.ok() && agreement.ok());
    std::cout << "[ RTK      ] cssrlib-kinematic " << rtk::ar_mode_name(k.mode) << ": canyon " << ours->fixed().epochs
              << " fixed, RTKLIB " << theirs->fixed().epochs << "; both fixed " << agreement->both_fixed
              << ", max distance " << agreement->max_distance_fixed_m << " m\n";
    EXPECT_GE(ours->fixed().epochs, theirs->fixed().epochs);
    EXPECT_GE(agreement->both_fixed, theirs->fixed().epochs * 9 / 10);
    // Within 3 cm of RTKLIB on every epoch both fixed, but where RTKLIB's fix rests on a satellite canyon rejects: at
    // 282769 (continuous) G14's phases jump by 9 cm on both frequencies (non-dispersive) before the satellite is
    // lost; canyon's post-fit test drops it, RTKLIB keeps it and is 6.3 cm off in height. There RTKLIB itself, run
    // with G14 excluded, must agree with canyon within 3 cm: the difference is G14's, not canyon's.
    std::vector<core::GpsTime> beyond;
    for (const core::Solution& c : run->solutions) {
      const core::Solution* r = test::nearest(*rtklib, c.time, 0.01);
      if (c.status == core::SolutionStatus::Fixed && r != nullptr && r->status == core::SolutionStatus::Fixed &&
          (c.p_E_m - r->p_E_m).norm() > kMaxDistanceToRtklibFixM) {
        beyond.push_back(c.time);
      }
    }
    EXPECT_LE(beyond.size(), 2U);
    if (beyond.empty()) continue;
    if (!test::have_rtklib()) {  // the epochs beyond cannot be explained: said below, after the other cases
      unexplained.push_back(rtk::ar_mode_name(k.mode));
      continue;
    }
    const fs::path dir = test::temp_dir("rtk") / "kinematic-without-g14";
    fs::create_directories(dir);
    const fs::path conf = dir / "rtklib.conf";
    {
      std::ifstream in(shared_data() / "cssrlib-kinematic-doy265/rtklib" /
                       (k.mode == rtk::ArMode::Continuous ? "rtk_kinematic.conf" : "rtk_kinematic_inst.conf"));
      std::ofstream out(conf);
      for (std::string line; std::getline(in, line);)
        out << (line.rfind("pos1-exclsats", 0) == 0 ? "pos1-exclsats =G14" : line) << "\n";
    }
    const fs::path data = shared_data() / "cssrlib-kinematic-doy265";
    const auto r = test::run_command("rnx2rtkp -k " + conf.string() + " -o " + (dir / "rtklib.pos").string() + " " +
                                     (data / "SEPT265G.21O").string() + " " + (data / "3034265G.21O").string() + " " +
                                     (data / "SEPT2650.21P").string() + " 2>/dev/null");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    auto without_g14 = io::read_pos_file((dir / "rtklib.pos").string());
    ASSERT_TRUE(without_g14.ok());
    for (const core::GpsTime& t : beyond) {
      const core::Solution* c = test::nearest(run->solutions, t, 0.01);
      const core::Solution* r14 = test::nearest(*without_g14, t, 0.01);
      ASSERT_TRUE(c != nullptr && r14 != nullptr);
      EXPECT_LE((c->p_E_m - r14->p_E_m).norm(), kMaxDistanceToRtklibFixM) << "tow " << t.tow_s;
      std::cout << "[ RTK      ] tow " << t.tow_s << ": canyon - RTKLIB "
                << (c->p_E_m - test::nearest(*rtklib, t, 0.01)->p_E_m).norm() << " m, canyon - RTKLIB without G14 "
                << (c->p_E_m - r14->p_E_m).norm() << " m\n";
    }
  }
  if (!unexplained.empty()) {
    GTEST_SKIP() << "RTKLIB rnx2rtkp not installed (scripts/setup.sh installs it): the fixes more than "
                 << std::lround(kMaxDistanceToRtklibFixM * 1000.0) << " mm from RTKLIB's (" << unexplained.front()
                 << (unexplained.size() > 1 ? ", " + unexplained.back() : std::string()) << ") were not checked "
                 << "against RTKLIB without G14";
  }
}

/// cssrlib-kinematic-doy265 with QZSS (RTKLIB 2.4.3 loses most of its fixes when QZSS is added), and on L1 alone
/// (where the ratio test alone accepts wrong single-epoch fixes): fixed epochs are checked against RTKLIB's
/// forward-backward fix-and-hold pseudo-reference shipped with the dataset (the only reference there is).
TEST(RtkRealData, CssrlibKinematicWithQzssAndOnL1Alone) {
  REQUIRE_DATA("cssrlib-kinematic-doy265");
  const Eigen::Vector3d base(-3959400.631, 3385704.533, 3667523.111);
  auto reference =
      io::read_pos_file((shared_data() / "cssrlib-kinematic-doy265/rtklib/pseudo_ref_fixed_only.pos").string());
  ASSERT_TRUE(reference.ok());
  struct Case {
    const char* name;
    rtk::ArMode mode;
    bool qzss;
    int frequencies;
    const char* rtklib_pos;  // RTKLIB's run in the same configuration, nullptr if none
    double min_fixed_fraction;
  };
  // With QZSS canyon keeps its own GPS + Galileo fix rate (100 % in both modes), against RTKLIB's drop from 22.8 % to
  // 12.8 % and from 90.8 % to 65.0 % (QZS-3's L1 code is 44 m off the others at some epochs: the post-fit code test
  // drops it).
  for (const Case& k :
       {Case{"continuous+J", rtk::ArMode::Continuous, true, 2, "rtk_kinematic_withqzss.pos", 1.0},
        Case{"instantaneous+J", rtk::ArMode::Instantaneous, true, 2, "rtk_kinematic_inst_withqzss.pos", 1.0},
        Case{"continuous L1", rtk::ArMode::Continuous, false, 1, nullptr, 0.9},
        Case{"instantaneous L1", rtk::ArMode::Instantaneous, false, 1, nullptr, 0.0}}) {
    auto run = run_rtk("kinematic", "cssrlib-kinematic-doy265/SEPT265G.21O", "cssrlib-kinematic-doy265/3034265G.21O",
                       {"cssrlib-kinematic-doy265/SEPT2650.21P"}, base, [&](config::ProcessConfig& c) {
                         c.rtk.ar_mode = k.mode;
                         c.rtk.observables.use_glonass = c.rtk.observables.use_beidou = false;
                         c.rtk.observables.use_qzss = k.qzss;
                         c.rtk.observables.num_frequencies = k.frequencies;
                       });
    ASSERT_TRUE(run.has_value());
    auto ours = eval::evaluate(run->solutions, nullptr);
    auto to_reference = eval::compare(run->solutions, *reference);
    ASSERT_TRUE(ours.ok() && to_reference.ok());
    std::cout << "[ RTK      ] cssrlib-kinematic " << k.name << ": canyon " << ours->fixed().epochs << "/"
              << run->summary.epochs << " fixed; max distance to the pseudo-reference "
              << to_reference->max_distance_fixed_m << " m on " << to_reference->both_fixed << " epochs\n";
    EXPECT_GE(ours->fixed().epochs, static_cast<int>(k.min_fixed_fraction * run->summary.epochs)) << k.name;
    EXPECT_LE(to_reference->max_distance_fixed_m, kWrongFixM) << k.name;
    if (k.rtklib_pos != nullptr) {
      auto rtklib = io::read_pos_file((shared_data() / "cssrlib-kinematic-doy265/rtklib" / k.rtklib_pos).string());
      ASSERT_TRUE(rtklib.ok());
      auto theirs = eval::evaluate(*rtklib, nullptr);
      ASSERT_TRUE(theirs.ok());
      EXPECT_GE(ours->fixed().epochs, theirs->fixed().epochs) << k.name;
    }
  }
}

/// m8p-galway-20181004 (u-blox M8P, L1 only, GPS + GLONASS with GLONASS AR off, a base logged with gaps of up to
/// 39 s): fix rate at least RTKLIB's (39 of 1180 epochs, the run shipped with the dataset), and fixed positions within
/// 10 cm of RTKLIB's where both are fixed. There is no truth; both programs fix in short, mostly disjoint runs.
TEST(RtkRealData, M8pSingleFrequencyFixRateAtLeastRtklibs) {
  REQUIRE_DATA("m8p-galway-20181004");
  const std::string dir = "m8p-galway-20181004/rinex/";
  auto base_header = io::RinexObsReader::open((shared_data() / dir / "20181004_base-20181004-1452.obs").string());
  ASSERT_TRUE(base_header.ok());
  ASSERT_TRUE(base_header->header().receiver.approx_position_E_m.has_value());
  auto run = run_rtk("m8p", dir + "20181004_rover-20181004-1532.obs", dir + "20181004_base-20181004-1452.obs",
                     {dir + "20181004_base-20181004-1452.nav"}, *base_header->header().receiver.approx_position_E_m,
                     [](config::ProcessConfig& c) {
                       c.rtk.observables.num_frequencies = 1;
                       c.rtk.observables.use_galileo = c.rtk.observables.use_beidou = false;
                       c.rtk.observables.use_qzss = false;  // RTKLIB's run: navsys 5 (GPS + GLONASS)
                       c.rtk.glonass_ar = false;
                     });
  ASSERT_TRUE(run.has_value());
  auto rtklib =
      io::read_pos_file((shared_data() / "m8p-galway-20181004/rtklib/20181004_run2_rtk_kinematic.pos").string());
  ASSERT_TRUE(rtklib.ok());
  auto ours = eval::evaluate(run->solutions, nullptr);
  auto theirs = eval::evaluate(*rtklib, nullptr);
  auto agreement = eval::compare(run->solutions, *rtklib);
  ASSERT_TRUE(ours.ok() && theirs.ok() && agreement.ok());
  std::cout << "[ RTK      ] m8p: canyon " << ours->fixed().epochs << " fixed, RTKLIB " << theirs->fixed().epochs
            << "; both fixed " << agreement->both_fixed << ", max distance " << agreement->max_distance_fixed_m
            << " m\n";
  EXPECT_EQ(run->summary.epochs, 1180);
  EXPECT_GE(ours->fixed().epochs, theirs->fixed().epochs);
  EXPECT_LE(agreement->max_distance_fixed_m, kWrongFixM);
}

TEST(RtkBadInput, MissingBasePositionAndBaseFromAnotherDay) {
  REQUIRE_DATA("cssrlib-static-doy078");
  // The rtklib-test-gsi-2005 base is from 2005: no epoch can be used; every epoch falls back to single point.
  auto run = run_rtk("other_day", "cssrlib-static-doy078/SEPT078M1.21O", "rtklib-test-gsi-2005/30400920.05o",
                     {"cssrlib-static-doy078/SEPT078M.21P"}, Eigen::Vector3d(-3959400.631, 3385704.533, 3667523.111));
  ASSERT_TRUE(run.has_value());
  EXPECT_EQ(run->summary.epochs, 60);
  EXPECT_EQ(run->summary.fixed, 0);
  bool warned = false;
  for (const auto& w : run->summary.warnings) warned = warned || w.find("another day") != std::string::npos;
  EXPECT_TRUE(warned);
  for (const auto& s : run->solutions) EXPECT_EQ(s.status, core::SolutionStatus::Single);

  // A base file without APPROX POSITION and no configured position: a clear error naming the base file.
  config::ProcessConfig c;
  c.mode = config::ProcessMode::Rtk;
  c.rover_obs = (shared_data() / "cssrlib-static-doy078/SEPT078M1.21O").string();
  const fs::path no_pos = test::temp_dir("rtk") / "base_without_position.obs";
  {
    std::ifstream in(shared_data() / "cssrlib-static-doy078/3034078M1.21O");
    std::ofstream out(no_pos);
    std::string line;
    while (std::getline(in, line)) {
      if (line.find("APPROX POSITION XYZ") == std::string::npos) out << line << '\n';
    }
  }
  c.base_obs = no_pos.string();
  c.nav = {(shared_data() / "cssrlib-static-doy078/SEPT078M.21P").string()};
  c.out = (test::temp_dir("rtk") / "x.pos").string();
  auto summary = commands::run_process(c);
  ASSERT_FALSE(summary.ok());
  EXPECT_NE(summary.error().message.find("no base position"), std::string::npos);
  EXPECT_EQ(summary.error().file, no_pos.string());
}

TEST(RtkBadInput, NoCommonSatellitesGivesSinglePointAndGoesOn) {
  REQUIRE_DATA("cssrlib-static-doy078");
  // Rover GPS only, base Galileo only (by excluding every GPS satellite at the base is not possible through the
  // config, so exclude constellations instead: rover and base then share none).
  auto run =
      run_rtk("no_common", "cssrlib-static-doy078/SEPT078M1.21O", "cssrlib-static-doy078/3034078M1.21O",
              {"cssrlib-static-doy078/SEPT078M.21P"}, Eigen::Vector3d(-3959400.631, 3385704.533, 3667523.111),
              [](config::ProcessConfig& c) {
                for (int prn = 1; prn <= 32; ++prn)
                  c.rtk.observables.excluded.push_back({core::Constellation::Gps, static_cast<std::uint8_t>(prn)});
                c.rtk.observables.use_galileo = c.rtk.observables.use_qzss = false;
              });
  ASSERT_TRUE(run.has_value());
  EXPECT_EQ(run->summary.epochs, 60);
  EXPECT_EQ(run->summary.fixed, 0);
  EXPECT_EQ(run->solutions.size(), 60U);
}

}  // namespace
}  // namespace canyon

namespace canyon {
namespace {

TEST(RtkOutput, NmeaGgaBesideThePosFile) {
  REQUIRE_DATA("cssrlib-static-doy078");
  const fs::path nmea = test::temp_dir("rtk") / "static.nmea";
  auto run = run_rtk("static_nmea", "cssrlib-static-doy078/SEPT078M1.21O", "cssrlib-static-doy078/3034078M1.21O",
                     {"cssrlib-static-doy078/SEPT078M.21P"}, Eigen::Vector3d(-3959400.631, 3385704.533, 3667523.111),
                     [&](config::ProcessConfig& c) { c.nmea_out = nmea.string(); });
  ASSERT_TRUE(run.has_value());
  std::ifstream in(nmea);
  std::string line;
  int sentences = 0;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    auto gga = io::parse_gga(line);
    ASSERT_TRUE(gga.ok()) << line << ": " << gga.error().message;
    EXPECT_EQ(gga->quality, 4) << line;  // RTK fixed
    ++sentences;
  }
  EXPECT_EQ(sentences, 60);
}

}  // namespace
}  // namespace canyon

namespace canyon {
namespace {

/// Adds a differential (rover - base) slant ionosphere to every GPS and Galileo signal of a rover file, as a ~20 km
/// baseline would see it: per satellite an L1 delay I_s(t) = offset_s + drift_s (t - t0) / 600 s, offsets uniform in
/// +-max_offset_m (fixed seed), drifts in +-max_offset_m / 3. It delays code by mu I and advances phase by mu I /
/// lambda cycles, mu = (lambda / lambda_L1)^2.
Status add_differential_ionosphere(const std::string& in, const std::string& out, double max_offset_m) {
  auto file = io::read_rinex_obs(in);
  if (!file) return file.error();
  std::mt19937_64 rng(20);
  std::uniform_real_distribution<double> offset(-max_offset_m, max_offset_m);
  std::uniform_real_distribution<double> drift(-max_offset_m / 3.0, max_offset_m / 3.0);
  std::map<core::SatelliteId, std::pair<double, double>> iono;  // satellite -> (offset, drift), m
  const core::GpsTime t0 = file->epochs.front().time;
  const double lambda_l1 = *core::wavelength_m(core::Constellation::Gps, core::SignalCode{'1', 'C'});
  for (core::ObsEpoch& epoch : file->epochs) {
    for (core::SatelliteObs& sat : epoch.sats) {
      auto it = iono.find(sat.sat);
      if (it == iono.end()) {
        const double o = offset(rng);
        it = iono.emplace(sat.sat, std::make_pair(o, drift(rng))).first;
      }
      const double delay_l1_m = it->second.first + it->second.second * (epoch.time - t0) / 600.0;
      for (core::SignalObs& s : sat.signals) {
        const auto lambda = core::wavelength_m(sat.sat.system, s.code);
        if (!lambda) continue;
        const double mu = (*lambda / lambda_l1) * (*lambda / lambda_l1);
        if (core::has_value(s.pseudorange_m)) s.pseudorange_m += mu * delay_l1_m;
        if (core::has_value(s.carrier_phase_cyc)) s.carrier_phase_cyc -= mu * delay_l1_m / *lambda;
      }
    }
  }
  return io::write_rinex_obs(out, file->header, file->epochs);
}

/// The ionosphere model for long baselines: with a severe 20 km differential ionosphere (SD delays up to 15 cm on L1,
/// ~7 ppm) added to the simulator's dynamic rover (exact truth), neglecting it gives hundreds of wrong fixes (measured:
/// all 519 fixes wrong, 3D RMSE 0.24 m); estimating it fixes 96 % with none wrong and 2 cm 3D RMSE (0.7 cm with 5 cm
/// delays).
TEST(RtkIonosphere, EstimatedIonosphereHandlesA20KmDifferentialDelay) {
  REQUIRE_DATA("instinct-spirent-rtk-sim");
  const std::string dir = "instinct-spirent-rtk-sim/iono-none_tropo-none/";
  const fs::path rover = test::temp_dir("rtk-iono") / "rover-with-iono.obs";
  const Status added = add_differential_ionosphere((shared_data() / dir / "Rover-dynamic_MO_Spirent.obs").string(),
                                                   rover.string(), 0.15);
  ASSERT_TRUE(added.ok()) << added.error().to_string();
  auto truth =
      eval::read_spirent_pva_csv((shared_data() / "instinct-spirent-rtk-sim/Rover-dynamic_PVA_Spirent.csv").string());
  ASSERT_TRUE(truth.ok()) << truth.error().to_string();
  const Eigen::Vector3d base(4157177.06580187, 671230.476590636, 4774767.03105544);
  std::map<rtk::IonosphereModel, eval::SolutionStats> stats;
  for (const rtk::IonosphereModel model : {rtk::IonosphereModel::Off, rtk::IonosphereModel::Estimate}) {
    auto run =
        run_rtk("iono", rover.string(), dir + "Base-static_MO_Spirent.obs",
                {"instinct-spirent-rtk-sim/RINEX_GN_Spirent.23N", "instinct-spirent-rtk-sim/RINEX_EN_Spirent.23L"},
                base, [&](config::ProcessConfig& c) {
                  c.rtk.observables.use_glonass = c.rtk.observables.use_beidou = false;
                  c.rtk.troposphere_saastamoinen = false;
                  c.spp.troposphere_saastamoinen = c.spp.ionosphere_klobuchar = false;
                  c.rtk.ionosphere = model;
                  c.rtk.iono_sigma_min_m = 0.1;  // the rover is within 2 km: the prior of a 20 km baseline
                });
    ASSERT_TRUE(run.has_value());
    eval::EvalOptions options;
    options.wrong_fix_threshold_m = kWrongFixM;
    auto s = eval::evaluate(run->solutions, *truth, options);
    ASSERT_TRUE(s.ok());
    std::cout << "[ RTK      ] instinct dynamic + 20 km ionosphere, ionosphere "
              << (model == rtk::IonosphereModel::Off ? "off" : "estimated") << ": " << s->fixed().epochs << "/"
              << run->summary.epochs << " fixed, 3D RMSE " << s->overall.rmse_3d_m << " m, wrong fixes "
              << s->wrong_fixes << "\n";
    stats.emplace(model, *s);
  }
  const eval::SolutionStats& estimated = stats.at(rtk::IonosphereModel::Estimate);
  const eval::SolutionStats& neglected = stats.at(rtk::IonosphereModel::Off);
  EXPECT_GE(estimated.fixed().epochs, 95 * estimated.epochs_in / 100);
  EXPECT_LE(estimated.overall.rmse_3d_m, 0.03);
  EXPECT_EQ(estimated.wrong_fixes, 0);
  // The perturbation matters: neglecting it is measurably worse.
  EXPECT_TRUE(neglected.overall.rmse_3d_m > 2.0 * estimated.overall.rmse_3d_m ||
              neglected.fixed().epochs < estimated.fixed().epochs * 9 / 10 || neglected.wrong_fixes > 0);
}

}  // namespace
}  // namespace canyon

namespace canyon {
namespace {

/// Epoch matching on the simulator's data (exact truth): a rover whose clock runs 5 ms behind the base's (time
/// tags 5 ms earlier, pseudoranges c * 5 ms shorter, phases f * 5 ms cycles fewer, as a receiver clock bias makes
/// them), and a base at a fifth of the rover's rate (every 5th epoch kept, so observations up to 4 s old are used).
TEST(RtkEpochMatching, FiveMillisecondClockOffsetAndLowerRateBase) {
  REQUIRE_DATA("instinct-spirent-rtk-sim");
  const std::string dir = "instinct-spirent-rtk-sim/iono-none_tropo-none/";
  const fs::path tmp = test::temp_dir("rtk-matching");
  auto rover = io::read_rinex_obs((shared_data() / dir / "Rover-static-2km-east_MO_Spirent.obs").string());
  auto base = io::read_rinex_obs((shared_data() / dir / "Base-static_MO_Spirent.obs").string());
  ASSERT_TRUE(rover.ok() && base.ok());
  constexpr double kOffsetS = -0.005;  // the rover tags come 5 ms before the base tags of the same instant
  for (core::ObsEpoch& epoch : rover->epochs) {
    epoch.time = epoch.time + kOffsetS;
    for (core::SatelliteObs& sat : epoch.sats) {
      for (core::SignalObs& s : sat.signals) {
        const auto f_hz = core::carrier_frequency_hz(sat.sat.system, s.code);
        if (core::has_value(s.pseudorange_m)) s.pseudorange_m += core::kSpeedOfLightMps * kOffsetS;
        if (core::has_value(s.carrier_phase_cyc) && f_hz) s.carrier_phase_cyc += *f_hz * kOffsetS;
      }
    }
  }
  std::vector<core::ObsEpoch> slow_base;
  for (std::size_t i = 0; i < base->epochs.size(); i += 5) slow_base.push_back(base->epochs[i]);
  const fs::path rover_path = tmp / "rover-minus-5ms.obs";
  const fs::path base_path = tmp / "base-0.2Hz.obs";
  ASSERT_TRUE(io::write_rinex_obs(rover_path.string(), rover->header, rover->epochs).ok());
  ASSERT_TRUE(io::write_rinex_obs(base_path.string(), base->header, slow_base).ok());
  const Eigen::Vector3d p_E_base(4157177.06580187, 671230.476590636, 4774767.03105544);
  const Eigen::Vector3d truth(4156857.1195929, 673209.028774142, 4774767.03105544);
  for (const auto mode : {rtk::ArMode::Continuous, rtk::ArMode::Instantaneous}) {
    auto run =
        run_rtk("matching", rover_path.string(), base_path.string(),
                {"instinct-spirent-rtk-sim/RINEX_GN_Spirent.23N", "instinct-spirent-rtk-sim/RINEX_EN_Spirent.23L"},
                p_E_base, [&](config::ProcessConfig& c) {
                  c.rtk.ar_mode = mode;
                  c.rtk.observables.use_glonass = c.rtk.observables.use_beidou = false;
                  c.rtk.troposphere_saastamoinen = false;
                  c.spp.troposphere_saastamoinen = c.spp.ionosphere_klobuchar = false;
                });
    ASSERT_TRUE(run.has_value());
    eval::EvalOptions options;
    options.wrong_fix_threshold_m = kWrongFixM;
    auto stats = eval::evaluate(run->solutions, eval::Truth::constant(truth), options);
    ASSERT_TRUE(stats.ok());
    std::cout << "[ RTK      ] instinct static, rover -5 ms, base 0.2 Hz, " << rtk::ar_mode_name(mode) << ": "
              << stats->fixed().epochs << "/" << run->summary.epochs << " fixed, 3D RMSE " << stats->overall.rmse_3d_m
              << " m\n";
    EXPECT_EQ(run->summary.epochs, static_cast<int>(rover->epochs.size()));  // no epoch dropped
    EXPECT_GE(stats->fixed().epochs, run->summary.epochs * 99 / 100);
    EXPECT_LE(stats->overall.rmse_3d_m, kMaxStaticRmse3dM);
    EXPECT_EQ(stats->wrong_fixes, 0);
  }
}

}  // namespace
}  // namespace canyon

namespace canyon {
namespace {

/// RINEX epoch flags: cycle-slip records (flag 6) are not observations and change nothing; a power failure (flag 1)
/// marks every phase as lost lock (the ambiguities restart, so the epoch is not fixed from the old ones).
TEST(RtkEpochFlags, CycleSlipRecordsAreNotObservationsAndPowerFailureResetsLock) {
  REQUIRE_DATA("cssrlib-static-doy078");
  const fs::path tmp = test::temp_dir("rtk-flags");
  auto rover = io::read_rinex_obs((shared_data() / "cssrlib-static-doy078/SEPT078M1.21O").string());
  ASSERT_TRUE(rover.ok());
  std::vector<core::ObsEpoch> with_slip_records;
  for (std::size_t i = 0; i < rover->epochs.size(); ++i) {
    with_slip_records.push_back(rover->epochs[i]);
    if (i == 20) {
      core::ObsEpoch records = rover->epochs[i];  // same time, "slip counts" in the observation fields
      records.flag = core::EpochFlag::CycleSlipRecords;
      for (core::SatelliteObs& sat : records.sats) {
        for (core::SignalObs& s : sat.signals) s.pseudorange_m = s.carrier_phase_cyc = 1.0;
      }
      with_slip_records.push_back(records);
    }
  }
  const fs::path slip_path = tmp / "rover-flag6.obs";
  ASSERT_TRUE(io::write_rinex_obs(slip_path.string(), rover->header, with_slip_records).ok());
  const Eigen::Vector3d base(-3959400.631, 3385704.533, 3667523.111);
  const auto run = [&](const std::string& path) {
    return run_rtk("flags", path, "cssrlib-static-doy078/3034078M1.21O", {"cssrlib-static-doy078/SEPT078M.21P"}, base);
  };
  auto plain = run("cssrlib-static-doy078/SEPT078M1.21O");
  auto slips = run(slip_path.string());
  ASSERT_TRUE(plain.has_value() && slips.has_value());
  ASSERT_EQ(plain->solutions.size(), slips->solutions.size());
  for (std::size_t i = 0; i < plain->solutions.size(); ++i) {
    EXPECT_LT((plain->solutions[i].p_E_m - slips->solutions[i].p_E_m).norm(), 1e-4) << i;
  }
  EXPECT_TRUE(std::any_of(slips->summary.warnings.begin(), slips->summary.warnings.end(),
                          [](const std::string& w) { return w.find("flag 6") != std::string::npos; }));

  rover->epochs[30].flag = core::EpochFlag::PowerFailure;
  const fs::path power_path = tmp / "rover-flag1.obs";
  ASSERT_TRUE(io::write_rinex_obs(power_path.string(), rover->header, rover->epochs).ok());
  auto power = run_rtk("flags", power_path.string(), "cssrlib-static-doy078/3034078M1.21O",
                       {"cssrlib-static-doy078/SEPT078M.21P"}, base,
                       [](config::ProcessConfig& c) { c.rtk.ar_mode = rtk::ArMode::Continuous; });
  ASSERT_TRUE(power.has_value());
  EXPECT_TRUE(std::any_of(power->summary.warnings.begin(), power->summary.warnings.end(),
                          [](const std::string& w) { return w.find("power failure") != std::string::npos; }));
  EXPECT_EQ(power->summary.epochs, 60);
}

}  // namespace
}  // namespace canyon
