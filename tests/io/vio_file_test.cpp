// vio.csv and timesync.csv readers: the contract, and each documented handling of bad input (error with file:line,
// or a dropped row with a warning).

#include "canyon/io/vio_file.hpp"

#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/rinex_test_util.hpp"

namespace canyon::io {
namespace {

std::string header(bool cross) {
  std::string h = "t_ns,px,py,pz,qx,qy,qz,qw";
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) h += ",cov_" + std::to_string(r) + "_" + std::to_string(c);
  }
  if (cross) {
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) h += ",xcov_" + std::to_string(r) + "_" + std::to_string(c);
    }
  }
  return h + "\n";
}

/// A row with position (x, 0, 0), identity rotation, covariance diag(var) and optionally cross-covariance c I.
std::string row(long long t_ns, double x, double var = 1e-4, double cross = -1.0) {
  std::ostringstream os;
  os << t_ns << "," << x << ",0,0,0,0,0,1";
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) os << "," << (r == c ? var : 0.0);
  }
  if (cross >= 0.0) {
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) os << "," << (r == c ? cross : 0.0);
    }
  }
  return os.str() + "\n";
}

TEST(VioFileTest, ReadsPosesCovariancesAndCrossCovariances) {
  test::TempDir tmp;
  const std::string path =
      tmp.write("vio.csv", header(true) + row(1000, 0.0, 1e-4, 0.0) + row(2000, 0.5) + row(3000, 1.0, 3e-4, 2e-4));
  // The second row lacks the cross-covariance columns: an error naming line 3.
  const auto bad = read_vio_csv(path);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().line, 3);
  EXPECT_NE(bad.error().to_string().find(path + ":3: expected 65 fields"), std::string::npos)
      << bad.error().to_string();

  const std::string good = tmp.write(
      "good.csv", header(true) + row(1000, 0.0, 1e-4, 0.0) + row(2000, 0.5, 2e-4, 1e-4) + row(3000, 1.0, 3e-4, 2e-4));
  const auto file = read_vio_csv(good);
  ASSERT_TRUE(file.ok()) << file.error().to_string();
  ASSERT_EQ(file->records.size(), 3U);
  EXPECT_TRUE(file->has_cross_covariance);
  EXPECT_EQ(file->records[1].t_ns, 2000);
  EXPECT_DOUBLE_EQ(file->records[1].T_OI.p.x(), 0.5);
  EXPECT_DOUBLE_EQ(file->records[1].covariance(4, 4), 2e-4);
  ASSERT_TRUE(file->records[1].cross_previous.has_value());
  EXPECT_DOUBLE_EQ((*file->records[1].cross_previous)(2, 2), 1e-4);
  EXPECT_FALSE(file->records[0].cross_previous.has_value());  // the first pose has no predecessor
  EXPECT_TRUE(file->warnings.empty());
}

TEST(VioFileTest, WithoutCrossCovarianceColumns) {
  test::TempDir tmp;
  const auto file = read_vio_csv(tmp.write("vio.csv", header(false) + row(1, 0.0) + row(2, 0.1)));
  ASSERT_TRUE(file.ok()) << file.error().to_string();
  EXPECT_FALSE(file->has_cross_covariance);
  EXPECT_FALSE(file->records[1].cross_previous.has_value());
}

TEST(VioFileTest, NonMonotonicTimeDropsThePoseWithAWarning) {
  test::TempDir tmp;
  const auto file = read_vio_csv(tmp.write("vio.csv", header(true) + row(1000, 0.0, 1e-4, 0.0) +
                                                          row(3000, 0.2, 1e-4, 1e-5) + row(2000, 0.1, 1e-4, 1e-5) +
                                                          row(4000, 0.3, 1e-4, 1e-5) + row(5000, 0.4, 1e-4, 1e-5)));
  ASSERT_TRUE(file.ok()) << file.error().to_string();
  ASSERT_EQ(file->records.size(), 4U);
  EXPECT_EQ(file->dropped_non_monotonic, 1);
  ASSERT_EQ(file->warnings.size(), 1U);
  EXPECT_NE(file->warnings[0].find(":4: time 2000 ns is not after the previous pose's 3000 ns"), std::string::npos)
      << file->warnings[0];
  // The row after the dropped one refers to it: its cross-covariance is not used.
  EXPECT_EQ(file->records[2].t_ns, 4000);
  EXPECT_FALSE(file->records[2].cross_previous.has_value());
  EXPECT_TRUE(file->records[3].cross_previous.has_value());
}

TEST(VioFileTest, NonPositiveDefiniteCovarianceDropsThePoseWithAWarning) {
  test::TempDir tmp;
  const auto file = read_vio_csv(tmp.write(
      "vio.csv", header(true) + row(1000, 0.0, 1e-4, 0.0) + row(2000, 0.1, -1e-4, 0.0) + row(3000, 0.2, 1e-4, 0.0)));
  ASSERT_TRUE(file.ok()) << file.error().to_string();
  EXPECT_EQ(file->records.size(), 2U);
  EXPECT_EQ(file->dropped_not_positive_definite, 1);
  ASSERT_EQ(file->warnings.size(), 1U);
  EXPECT_NE(file->warnings[0].find(":3: covariance is not positive definite"), std::string::npos) << file->warnings[0];
  EXPECT_FALSE(file->records[1].cross_previous.has_value());
}

TEST(VioFileTest, BadInputIsAnErrorNamingTheLine) {
  test::TempDir tmp;
  struct Case {
    const char* name;
    std::string content;
    int line;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"empty", "", 1, "no header row"},
      {"header", "t,x,y,z\n" + row(1, 0.0), 1, "not a VIO file"},
      {"fields", header(false) + "1,0,0,0,0,0,0,1\n" + row(2, 0.0), 2, "expected 29 fields"},
      {"number", header(false) + row(1, 0.0).replace(row(1, 0.0).find(",0,0,0,0,1,"), 2, ",x"), 2, "not a number"},
      {"nan", header(false) + row(1, 0.0).replace(2, 1, "nan"), 2, "not finite"},
      {"time", header(false) + std::string("1.5") + row(1, 0.0).substr(1), 2, "t_ns is not an integer"},
      {"no rows", header(false), 1, "no usable pose"},
  };
  for (const Case& c : cases) {
    const auto file = read_vio_csv(tmp.write(std::string(c.name) + ".csv", c.content));
    ASSERT_FALSE(file.ok()) << c.name;
    EXPECT_EQ(file.error().line, c.line) << c.name << ": " << file.error().to_string();
    EXPECT_NE(file.error().message.find(c.message), std::string::npos) << c.name << ": " << file.error().to_string();
  }
  // A zero quaternion in a well-formed row.
  std::string zero_q = row(1, 0.0);
  zero_q.replace(zero_q.find(",0,0,0,0,1,"), 11, ",0,0,0,0,0,");
  const auto file = read_vio_csv(tmp.write("zero_q.csv", header(false) + zero_q));
  ASSERT_FALSE(file.ok());
  EXPECT_NE(file.error().message.find("not a rotation"), std::string::npos) << file.error().to_string();
}

TEST(VioFileTest, LastRowCutShortIsDroppedWithAWarning) {
  test::TempDir tmp;
  std::string last = row(3000, 0.2);
  last.resize(last.size() / 2);  // no end of line either
  const auto file = read_vio_csv(tmp.write("vio.csv", header(false) + row(1000, 0.0) + row(2000, 0.1) + last));
  ASSERT_TRUE(file.ok()) << file.error().to_string();
  EXPECT_EQ(file->records.size(), 2U);
  ASSERT_EQ(file->warnings.size(), 1U);
  EXPECT_NE(file->warnings[0].find(":4: expected 29 fields"), std::string::npos) << file->warnings[0];
  EXPECT_NE(file->warnings[0].find("cut short"), std::string::npos) << file->warnings[0];
}

// A long file (10,000 rows, as a 17-minute VIO at 10 Hz): every row where it belongs, the warnings in line order, the
// successor of each dropped row without its cross-covariance, and the first bad row in the file is the error, before
// later bad rows of any kind.
TEST(VioFileTest, ALongFileGivesItsRowsWarningsAndFirstErrorInLineOrder) {
  test::TempDir tmp;
  constexpr int kRows = 10000;
  const auto line_of = [](int index) { return index + 2; };  // after the header
  std::vector<std::string> rows;
  for (int i = 0; i < kRows; ++i) rows.push_back(row(1000LL * (i + 1), 0.001 * i, 1e-4, 1e-5));
  rows[3000] = row(1000LL * 2999, 0.0, 1e-4, 1e-5);   // non-monotonic
  rows[4095] = row(1000LL * 4096, 0.0, -1e-4, 1e-5);  // not positive definite
  rows[9000] = row(1000LL * 9001, 0.0, -1e-4, 1e-5);  // and again
  const auto join = [](const std::vector<std::string>& r) {
    std::string text = header(true);
    for (const std::string& x : r) text += x;
    return text;
  };
  const auto file = read_vio_csv(tmp.write("long.csv", join(rows)));
  ASSERT_TRUE(file.ok()) << file.error().to_string();
  ASSERT_EQ(file->records.size(), static_cast<std::size_t>(kRows - 3));
  EXPECT_EQ(file->dropped_non_monotonic, 1);
  EXPECT_EQ(file->dropped_not_positive_definite, 2);
  ASSERT_EQ(file->warnings.size(), 3U);
  EXPECT_NE(file->warnings[0].find(":" + std::to_string(line_of(3000)) + ": time"), std::string::npos);
  EXPECT_NE(file->warnings[1].find(":" + std::to_string(line_of(4095)) + ": covariance"), std::string::npos);
  EXPECT_NE(file->warnings[2].find(":" + std::to_string(line_of(9000)) + ": covariance"), std::string::npos);
  for (const VioRecord& r : file->records) {
    const int i = r.line - 2;
    EXPECT_EQ(r.t_ns, 1000LL * (i + 1)) << r.line;
    EXPECT_DOUBLE_EQ(r.T_OI.p.x(), 0.001 * i) << r.line;
    // The rows after a dropped one (3000, 4095 and 9000) lose their cross-covariance.
    EXPECT_EQ(r.cross_previous.has_value(), i != 0 && i != 3001 && i != 4096 && i != 9001) << r.line;
  }

  // The first bad row is the error: a bad quaternion before a bad number before a row of the wrong length.
  std::vector<std::string> bad = rows;
  bad[5000].replace(bad[5000].find(",0,0,0,1,"), 9, ",0,0,0,0,");
  bad[7000].replace(bad[7000].find(",0,0,0,1,"), 3, ",x,");
  bad[9500] = "1,2,3\n";
  const auto first = read_vio_csv(tmp.write("bad.csv", join(bad)));
  ASSERT_FALSE(first.ok());
  EXPECT_EQ(first.error().line, line_of(5000)) << first.error().to_string();
  EXPECT_NE(first.error().message.find("not a rotation"), std::string::npos) << first.error().to_string();
  bad[5000] = rows[5000];
  const auto second = read_vio_csv(tmp.write("bad2.csv", join(bad)));
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.error().line, line_of(7000)) << second.error().to_string();
  bad[7000] = rows[7000];
  const auto third = read_vio_csv(tmp.write("bad3.csv", join(bad)));
  ASSERT_FALSE(third.ok());
  EXPECT_EQ(third.error().line, line_of(9500)) << third.error().to_string();
  EXPECT_NE(third.error().message.find("expected 65 fields"), std::string::npos) << third.error().to_string();
}

TEST(TimeSyncFileTest, ReadsPairsAndRefusesBadOnes) {
  test::TempDir tmp;
  const auto file = read_timesync_csv(tmp.write("sync.csv",
                                                "t_ns,gps_week,gps_tow_s\n1234500000000,2266,316800.000\n"
                                                "1235500000000,2266,316801.000\n"));
  ASSERT_TRUE(file.ok()) << file.error().to_string();
  ASSERT_EQ(file->pairs.size(), 2U);
  EXPECT_EQ(file->pairs[1].t_ns, 1235500000000);
  EXPECT_EQ(file->pairs[1].time.week, 2266);
  EXPECT_DOUBLE_EQ(file->pairs[1].time.tow_s, 316801.0);
  EXPECT_EQ(file->pairs[1].line, 3);

  const auto header = read_timesync_csv(tmp.write("h.csv", "t,week,tow\n1,2,3\n"));
  ASSERT_FALSE(header.ok());
  EXPECT_EQ(header.error().line, 1);
  const auto tow = read_timesync_csv(tmp.write("tow.csv", "t_ns,gps_week,gps_tow_s\n1,2266,604800\n"));
  ASSERT_FALSE(tow.ok());
  EXPECT_EQ(tow.error().line, 2);
  const auto none = read_timesync_csv(tmp.write("none.csv", "t_ns,gps_week,gps_tow_s\n"));
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("no time-sync pair"), std::string::npos);
}

}  // namespace
}  // namespace canyon::io
