// Truth sources: constant point, interpolated trajectory, the readers and their errors.

#include "canyon/eval/truth.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"

namespace canyon::eval {
namespace {

const core::GpsTime kT0{2244, 36000.0};

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("canyon_eval_" + name);
  std::ofstream(path) << text;
  return path.string();
}

TEST(Truth, ConstantIsTheSameEverywhere) {
  const Truth truth = Truth::constant({1.0, 2.0, 3.0});
  EXPECT_TRUE(truth.is_constant());
  EXPECT_EQ(*truth.position_at(kT0), Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_EQ(*truth.position_at(core::GpsTime{100, 0.0}), Eigen::Vector3d(1.0, 2.0, 3.0));
}

TEST(Truth, InterpolatesLinearlyAndExtrapolatesAtMostTheLimit) {
  auto truth = Truth::from_samples({{kT0, {0, 0, 0}}, {kT0 + 1.0, {1, 2, 0}}, {kT0 + 2.0, {1, 2, 4}}});
  ASSERT_TRUE(truth.ok());
  EXPECT_TRUE(truth->position_at(kT0 + 0.25)->isApprox(Eigen::Vector3d(0.25, 0.5, 0), 1e-9));
  EXPECT_TRUE(truth->position_at(kT0 + 1.5)->isApprox(Eigen::Vector3d(1, 2, 2), 1e-9));
  EXPECT_EQ(*truth->position_at(kT0 + 1.0), Eigen::Vector3d(1, 2, 0));
  // 0.1 s beyond either end: the end segment extended; 0.3 s: nothing.
  EXPECT_TRUE(truth->position_at(kT0 + 2.1)->isApprox(Eigen::Vector3d(1, 2, 4.4), 1e-9));
  EXPECT_TRUE(truth->position_at(kT0 - 0.1)->isApprox(Eigen::Vector3d(-0.1, -0.2, 0), 1e-9));
  EXPECT_FALSE(truth->position_at(kT0 + 2.3).has_value());
  EXPECT_FALSE(truth->position_at(kT0 - 0.3).has_value());
}

TEST(Truth, NoPositionInsideAGap) {
  auto truth = Truth::from_samples({{kT0, {0, 0, 0}}, {kT0 + 10.0, {10, 0, 0}}});
  ASSERT_TRUE(truth.ok());
  EXPECT_FALSE(truth->position_at(kT0 + 5.0).has_value());
  TruthOptions wide;
  wide.max_gap_s = 20.0;
  auto wide_truth = Truth::from_samples({{kT0, {0, 0, 0}}, {kT0 + 10.0, {10, 0, 0}}}, wide);
  ASSERT_TRUE(wide_truth.ok());
  EXPECT_TRUE(wide_truth->position_at(kT0 + 5.0)->isApprox(Eigen::Vector3d(5, 0, 0), 1e-9));
}

TEST(Truth, RejectsUnorderedSamples) {
  EXPECT_FALSE(Truth::from_samples({}).ok());
  const auto result = Truth::from_samples({{kT0 + 1.0, {0, 0, 0}}, {kT0, {0, 0, 0}}});
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().message.find("sample 1"), std::string::npos);
}

TEST(TruthReaders, SpirentPvaCsvAcrossTheCycle) {
  const std::string path =
      write_temp("pva.csv",
                 "Time [s],GpsCycle,GpsWeek,GpsToW [s],Pos ECEF X [m],Pos ECEF Y [m],Pos ECEF Z [m],Vel ECEF X [m/s]\n"
                 "0,2,196,36000,4157161.126,671329.198,4774767.031,-3.8893\n"
                 "0.1,2,196,36000.1,4157160.7374,671329.1337,4774767.376,-3.8828\n");
  const auto truth = read_spirent_pva_csv(path);
  ASSERT_TRUE(truth.ok()) << truth.error().to_string();
  ASSERT_EQ(truth->samples().size(), 2U);
  EXPECT_EQ(truth->samples()[0].time.week, 2244);
  EXPECT_DOUBLE_EQ(truth->samples()[1].time.tow_s, 36000.1);
  const auto mid = truth->position_at(core::GpsTime{2244, 36000.05});
  ASSERT_TRUE(mid.has_value());
  EXPECT_NEAR(mid->x(), (4157161.126 + 4157160.7374) / 2, 1e-6);
  // The spec chooses this reader from the header.
  EXPECT_TRUE(parse_truth_spec(path).ok());
}

TEST(TruthReaders, ErrorsNameFileAndLine) {
  const std::string bad_number = write_temp(
      "pva_bad.csv",
      "GpsCycle,GpsWeek,GpsToW [s],Pos ECEF X [m],Pos ECEF Y [m],Pos ECEF Z [m]\n2,196,36000,1,2,3\n2,196,x,1,2,3\n");
  const auto a = read_spirent_pva_csv(bad_number);
  ASSERT_FALSE(a.ok());
  EXPECT_EQ(a.error().file, bad_number);
  EXPECT_EQ(a.error().line, 3);

  const std::string missing_column = write_temp("pva_nocol.csv", "GpsWeek,GpsToW [s],Pos ECEF X [m]\n196,1,2\n");
  const auto b = read_spirent_pva_csv(missing_column);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("Pos ECEF Y [m]"), std::string::npos);
  EXPECT_EQ(b.error().line, 1);

  const std::string backwards = write_temp("truth_back.csv", "gps_week,gps_tow_s,x,y,z\n2244,2,1,2,3\n2244,1,1,2,3\n");
  const auto c = read_truth_csv(backwards);
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error().line, 3);

  EXPECT_FALSE(read_truth_pos("/nonexistent/truth.pos").ok());
}

TEST(TruthReaders, CanyonCsvAndWeekTowXyzPos) {
  const std::string csv = write_temp("truth.csv",
                                     "gps_week,gps_tow_s,x,y,z,qx,qy,qz,qw\n2244,1,1,2,3,0,0,0,1\n"
                                     "2244,2,2,2,3,0,0,0,1\n");
  const auto a = parse_truth_spec(csv);
  ASSERT_TRUE(a.ok()) << a.error().to_string();
  EXPECT_TRUE(a->position_at(core::GpsTime{2244, 1.5})->isApprox(Eigen::Vector3d(1.5, 2, 3), 1e-9));

  const std::string pos = write_temp("truth.pos",
                                     "% week tow x y z Q ns\n2244 36000.000 4157161.1260 671329.1980 "
                                     "4774767.0310 1 0\n2244 36000.100 4157160.7374 671329.1337 "
                                     "4774767.3760 1 0\n");
  const auto b = parse_truth_spec(pos);
  ASSERT_TRUE(b.ok()) << b.error().to_string();
  EXPECT_NEAR(b->position_at(core::GpsTime{2244, 36000.1})->z(), 4774767.376, 1e-6);
}

TEST(TruthSpec, ConstantPoints) {
  const auto ecef = parse_truth_spec("ecef:-3962108.673,3381309.574,3668678.638");
  ASSERT_TRUE(ecef.ok());
  EXPECT_EQ(*ecef->position_at(kT0), Eigen::Vector3d(-3962108.673, 3381309.574, 3668678.638));
  const auto llh = parse_truth_spec("llh:35.13469901,136.97757549,104.8626");
  ASSERT_TRUE(llh.ok());
  const core::Geodetic g = core::ecef_to_geodetic(*llh->position_at(kT0));
  EXPECT_NEAR(g.lat_rad * core::kRadToDeg, 35.13469901, 1e-9);
  EXPECT_NEAR(g.height_m, 104.8626, 1e-4);
  EXPECT_FALSE(parse_truth_spec("ecef:1,2").ok());
  EXPECT_FALSE(parse_truth_spec("ecef:1,2,x").ok());
  EXPECT_FALSE(parse_truth_spec("llh:95,0,0").ok());
  EXPECT_FALSE(parse_truth_spec("").ok());
}

}  // namespace
}  // namespace canyon::eval
