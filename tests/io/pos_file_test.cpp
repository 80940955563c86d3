#include "canyon/io/pos_file.hpp"

#include <filesystem>
#include <fstream>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

#include "canyon/core/geodesy.hpp"

namespace canyon::io {
namespace {

namespace fs = std::filesystem;

core::Solution sample_solution() {
  core::Solution s;
  s.time = core::GpsTime{2176, 282600.5};
  s.status = core::SolutionStatus::Float;
  s.p_E_m = Eigen::Vector3d(-3959400.631, 3385704.533, 3667523.111);
  Eigen::Matrix3d A;
  A << 0.02, 0.005, -0.003, 0.0, 0.03, 0.004, 0.0, 0.0, 0.05;
  s.P_E_m2 = A.transpose() * A;
  s.num_satellites = 17;
  s.age_s = 1.5;
  s.ratio = 2.4;
  return s;
}

TEST(PosFileTest, RoundTripsBothCoordinateFormsAndTimeFormats) {
  const core::Solution s = sample_solution();
  for (const PosCoordinates coordinates : {PosCoordinates::Llh, PosCoordinates::Ecef}) {
    for (const PosTimeFormat time_format : {PosTimeFormat::WeekTow, PosTimeFormat::Calendar}) {
      const fs::path path = fs::temp_directory_path() / "canyon_pos_roundtrip.pos";
      auto writer = PosWriter::create(path.string(), {coordinates, time_format, {"program   : test"}});
      ASSERT_TRUE(writer.ok());
      ASSERT_TRUE(writer->write(s).ok());
      ASSERT_TRUE(writer->close().ok());
      auto read = read_pos_file(path.string());
      ASSERT_TRUE(read.ok()) << read.error().to_string();
      ASSERT_EQ(read->size(), 1U);
      const core::Solution& r = read->front();
      EXPECT_NEAR(r.time - s.time, 0.0, 1e-3);
      EXPECT_LT((r.p_E_m - s.p_E_m).norm(), 1e-3);
      EXPECT_EQ(r.status, s.status);
      EXPECT_EQ(r.num_satellites, s.num_satellites);
      EXPECT_NEAR(r.age_s, s.age_s, 0.01);
      EXPECT_NEAR(r.ratio, s.ratio, 0.1);
      EXPECT_LT((r.P_E_m2 - s.P_E_m2).cwiseAbs().maxCoeff(), 2e-4);  // 4-decimal standard deviations
    }
  }
}

TEST(PosFileTest, WritesRtklibColumnLayout) {
  const std::string line = format_pos_record(sample_solution(), PosCoordinates::Llh, PosTimeFormat::WeekTow);
  EXPECT_EQ(line.substr(0, 15), "2176 282600.500");
  EXPECT_NE(line.find("   2  17 "), std::string::npos) << line;
}

TEST(PosFileTest, ReadsRtklibOutput) {
  const fs::path pos = fs::path(CANYON_SHARED_DATA_DIR) / "rtklib-test-gsi-2005/rtklib/rtk_kinematic.pos";
  if (!fs::exists(pos)) GTEST_SKIP() << "shared dataset not present: " << pos;
  auto read = read_pos_file(pos.string());
  ASSERT_TRUE(read.ok()) << read.error().to_string();
  ASSERT_EQ(read->size(), 115U);
  EXPECT_EQ(read->front().time.week, 1316);
  EXPECT_NEAR(read->front().time.tow_s, 518400.0, 1e-9);
  EXPECT_EQ(read->front().status, core::SolutionStatus::Fixed);
  const core::Geodetic g = core::ecef_to_geodetic(read->front().p_E_m);
  EXPECT_NEAR(g.height_m, 70.2724, 1e-4);
}

TEST(PosFileTest, MalformedRecordNamesFileAndLine) {
  const fs::path path = fs::temp_directory_path() / "canyon_bad.pos";
  std::ofstream(path) << "% header\n2176 282600.000 35.1 139.5 47.0 1 10\n2176 abc\n";
  auto read = read_pos_file(path.string());
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.error().line, 3);
  EXPECT_EQ(read.error().file, path.string());
}

TEST(PosFileTest, UnwritablePathIsAnError) {
  auto writer = PosWriter::create("/proc/canyon-cannot-create/x.pos", {});
  ASSERT_FALSE(writer.ok());
  EXPECT_NE(writer.error().message.find("cannot create"), std::string::npos);
}

}  // namespace
}  // namespace canyon::io
