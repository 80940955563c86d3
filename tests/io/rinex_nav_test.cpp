// RINEX navigation reader and writer: every shared nav file (record counts per system), a hand-made mixed file with
// all five systems checked field by field (times converted to GPST), RINEX 2 GLONASS, malformed inputs (each error
// names the file and the line), gzip input and a read -> write -> read round trip.

#include "canyon/io/rinex_nav.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <zlib.h>

namespace canyon::io {
namespace {

namespace fs = std::filesystem;
using core::Constellation;

// clang-format off
const std::vector<std::string> kHeader = {
    "     3.04           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE",
    "sbf2rin-15.9.0                          20240624 104231 UTC PGM / RUN BY / DATE ",
    "GPSA   1.8626E-08  2.2352E-08 -1.1921E-07 -5.9605E-08       IONOSPHERIC CORR    ",
    "GPSB   1.2902E+05  1.6384E+05 -1.9661E+05 -2.6214E+05       IONOSPHERIC CORR    ",
    "    18                                                      LEAP SECONDS        ",
    "                                                            END OF HEADER       ",
};
const std::vector<std::string> kGps = {
    "G05 2024 06 24 10 00 00-1.774230040610E-04-1.364242052659E-12 0.000000000000E+00",
    "     7.200000000000E+01-9.821875000000E+01 4.293035965037E-09 1.714815412488E+00",
    "    -5.291774868965E-06 5.927642923780E-03 1.830980181694E-06 5.153635631561E+03",
    "     1.224000000000E+05 3.352761268616E-08 2.520897825810E+00-5.774199962616E-08",
    "     9.719266524177E-01 3.536250000000E+02 1.273307347665E+00-8.275344701323E-09",
    "    -2.610823036973E-10 1.000000000000E+00 2.320000000000E+03 0.000000000000E+00",
    "     2.000000000000E+00 0.000000000000E+00-1.071020960808E-08 7.200000000000E+01",
    "     1.152180000000E+05 4.000000000000E+00",
};
const std::vector<std::string> kGlonass = {
    "R01 2024 06 24 08 15 00 8.934084326029E-05 9.094947017729E-13 1.152000000000E+05",
    "    -1.373688769531E+04-1.554378509521E+00 9.313225746155E-10 0.000000000000E+00",
    "    -3.309238281250E+03-2.458472251892E+00 1.862645149231E-09 1.000000000000E+00",
    "     2.124241259766E+04-1.386628150940E+00-1.862645149231E-09 0.000000000000E+00",
};
const std::vector<std::string> kBeidou = {
    "C01 2024 06 24 08 00 00 9.039411088452E-04 2.186695269302E-12 0.000000000000E+00",
    "     1.000000000000E+00 3.987812500000E+02 1.168655822063E-08-7.785119710056E-01",
    "     1.305714249611E-05 2.352053998038E-04-1.721968874335E-05 6.493358730316E+03",
    "     1.152000000000E+05 3.771856427193E-08-1.376223151778E+00-3.306195139885E-08",
    "     6.493194956776E-02 5.192812500000E+02 5.103894865136E-01-1.047865076358E-08",
    "     2.235807416067E-10 0.000000000000E+00 9.640000000000E+02 0.000000000000E+00",
    "     2.000000000000E+00 0.000000000000E+00-4.900000000000E-09-1.000000000000E-08",
    "     1.152276000000E+05 0.000000000000E+00",
};
const std::vector<std::string> kGalileo = {
    "E04 2024 06 24 08 00 00-4.288260824978E-04-9.166001291305E-12 0.000000000000E+00",
    "     6.500000000000E+01-1.331562500000E+02 2.712612991219E-09 1.450514434286E+00",
    "    -6.210058927536E-06 3.254675539210E-04 1.124665141106E-05 5.440636682510E+03",
    "     1.152000000000E+05-1.862645149231E-09-2.626136897440E+00 2.980232238770E-08",
    "     9.617908215797E-01 1.019375000000E+02-1.068999055553E+00-5.213788603794E-09",
    "     4.478757986819E-10 5.170000000000E+02 2.320000000000E+03",
    "     3.120000000000E+00 0.000000000000E+00-1.629814505577E-09-2.328306436539E-09",
    "     1.160750000000E+05",
};
const std::vector<std::string> kQzss = {
    "J02 2024 06 24 09 00 00-3.986060619354E-07-1.136868377216E-13 0.000000000000E+00",
    "     1.290000000000E+02-1.784687500000E+02 2.984410026942E-09 4.570693965350E-01",
    "    -6.083399057388E-06 7.549538882449E-02 1.047551631927E-05 6.493158788681E+03",
    "     1.188000000000E+05-1.095235347748E-06-3.120861366460E-01-3.259629011154E-07",
    "     7.082430271078E-01-1.216250000000E+02-1.584118644831E+00-2.884405861368E-09",
    "    -7.832469110920E-10 2.000000000000E+00 2.320000000000E+03 1.000000000000E+00",
    "     4.000000000000E+00 1.000000000000E+00 1.396983861923E-09 8.970000000000E+02",
    "     1.157050000000E+05 0.000000000000E+00",
};
const std::vector<std::string> kSbas = {
    "S27 2024 06 24 08 19 12 0.000000000000E+00 0.000000000000E+00 1.163680000000E+05",
    "     4.063997440000E+04 0.000000000000E+00 0.000000000000E+00 6.300000000000E+01",
    "     1.123500000000E+03 0.000000000000E+00 0.000000000000E+00 3.276700000000E+04",
    "     0.000000000000E+00 0.000000000000E+00 0.000000000000E+00 2.700000000000E+01",
};
const std::vector<std::string> kGlonassV2 = {
    "     2.11           G: GLONASS NAV DATA                     RINEX VERSION / TYPE",
    "    18                                                      LEAP SECONDS        ",
    "                                                            END OF HEADER       ",
    " 1 24  6 24  8 15  0.0 8.934084326029D-05 9.094947017729D-13 2.880000000000D+04",
    "   -1.373688769531D+04-1.554378509521D+00 9.313225746155D-10 0.000000000000D+00",
    "   -3.309238281250D+03-2.458472251892D+00 1.862645149231D-09 1.000000000000D+00",
    "    2.124241259766D+04-1.386628150940D+00-1.862645149231D-09 0.000000000000D+00",
};
// clang-format on

std::vector<std::string> concat(std::initializer_list<std::vector<std::string>> parts) {
  std::vector<std::string> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

class RinexNavTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("canyon_nav_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::vector<std::string>& lines) {
    std::string path = (dir_ / name).string();
    std::ofstream os(path);
    for (const auto& l : lines) os << l << '\n';
    return path;
  }
  std::string write_gzip(const std::string& name, const std::vector<std::string>& lines) {
    std::string path = (dir_ / name).string();
    gzFile f = gzopen(path.c_str(), "wb");
    for (const auto& l : lines) {
      gzputs(f, l.c_str());
      gzputs(f, "\n");
    }
    gzclose(f);
    return path;
  }

  fs::path dir_;
};

std::map<Constellation, int> counts(const core::NavigationData& nav) {
  std::map<Constellation, int> c;
  for (const auto& e : nav.kepler) ++c[e.sat.system];
  for (const auto& g : nav.glonass) ++c[g.sat.system];
  return c;
}

TEST_F(RinexNavTest, MixedFileAllSystemsToGpst) {
  const std::string path = write("mixed.nav", concat({kHeader, kGps, kGlonass, kSbas, kBeidou, kGalileo, kQzss}));
  const Result<RinexNavFile> r = read_rinex_nav(path);
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  const core::NavigationData& nav = r->nav;
  ASSERT_EQ(nav.kepler.size(), 4u);
  ASSERT_EQ(nav.glonass.size(), 1u);
  ASSERT_EQ(r->warnings.size(), 1u);  // the SBAS record
  EXPECT_NE(r->warnings[0].find("skipped 1"), std::string::npos);
  ASSERT_TRUE(nav.gps_klobuchar.has_value());
  EXPECT_DOUBLE_EQ(nav.gps_klobuchar->alpha[2], -1.1921e-07);
  EXPECT_DOUBLE_EQ(nav.gps_klobuchar->beta[3], -2.6214e+05);
  EXPECT_EQ(nav.leap_seconds, 18);

  // 2024-06-24 is a Monday of GPS week 2320: 00:00 GPST = tow 86400.
  const core::KeplerEphemeris& g = nav.kepler[0];
  EXPECT_EQ(g.sat.to_string(), "G05");
  EXPECT_EQ(g.toc, (core::GpsTime{2320, 86400.0 + 36000.0}));
  EXPECT_EQ(g.toe, (core::GpsTime{2320, 122400.0}));
  EXPECT_EQ(g.transmission_time, (core::GpsTime{2320, 115218.0}));
  EXPECT_DOUBLE_EQ(g.af0_s, -1.774230040610E-04);
  EXPECT_DOUBLE_EQ(g.sqrt_a_sqrtm, 5.153635631561E+03);
  EXPECT_EQ(g.iode, 72);
  EXPECT_EQ(g.iodc, 72);
  EXPECT_DOUBLE_EQ(g.accuracy_m, 2.0);
  EXPECT_DOUBLE_EQ(g.tgd_s[0], -1.071020960808E-08);
  EXPECT_DOUBLE_EQ(g.fit_interval_h, 4.0);
  EXPECT_EQ(g.data_source, 1);

  // BeiDou: toc 08:00:00 BDT = 08:00:14 GPST; toe BDT week 964 sow 115200 = GPS week 2320, 115214.
  const core::KeplerEphemeris& c = nav.kepler[1];
  EXPECT_EQ(c.sat.to_string(), "C01");
  EXPECT_EQ(c.toc, (core::GpsTime{2320, 86400.0 + 28814.0}));
  EXPECT_EQ(c.toe, (core::GpsTime{2320, 115214.0}));
  EXPECT_DOUBLE_EQ(c.toe_sow_s, 115200.0);
  EXPECT_DOUBLE_EQ(c.tgd_s[0], -4.9e-9);
  EXPECT_DOUBLE_EQ(c.tgd_s[1], -1.0e-8);
  EXPECT_EQ(c.iode, 1);
  EXPECT_EQ(c.iodc, 0);
  EXPECT_EQ(c.transmission_time, (core::GpsTime{2320, 115241.6}));

  const core::KeplerEphemeris& e = nav.kepler[2];
  EXPECT_EQ(e.sat.to_string(), "E04");
  EXPECT_EQ(e.toe, (core::GpsTime{2320, 115200.0}));
  EXPECT_EQ(e.data_source, 517);
  EXPECT_DOUBLE_EQ(e.accuracy_m, 3.12);
  EXPECT_DOUBLE_EQ(e.tgd_s[0], -1.629814505577E-09);
  EXPECT_DOUBLE_EQ(e.tgd_s[1], -2.328306436539E-09);
  EXPECT_EQ(e.iode, 65);

  const core::KeplerEphemeris& j = nav.kepler[3];
  EXPECT_EQ(j.sat.to_string(), "J02");
  EXPECT_EQ(j.health, 1);
  EXPECT_EQ(j.iodc, 897);

  // GLONASS: 08:15:00 UTC + 18 s; frame time 115200 s of the UTC week.
  const core::GlonassEphemeris& r01 = nav.glonass[0];
  EXPECT_EQ(r01.sat.to_string(), "R01");
  EXPECT_EQ(r01.toe, (core::GpsTime{2320, 86400.0 + 8 * 3600 + 15 * 60 + 18}));
  EXPECT_EQ(r01.frame_time, (core::GpsTime{2320, 115218.0}));
  EXPECT_DOUBLE_EQ(r01.tau_n_s, 8.934084326029E-05);
  EXPECT_DOUBLE_EQ(r01.gamma_n, 9.094947017729E-13);
  EXPECT_EQ(r01.frequency_channel, 1);
  EXPECT_DOUBLE_EQ(r01.p_E_m.x(), -1.373688769531E+07);
  EXPECT_DOUBLE_EQ(r01.v_E_mps.y(), -2.458472251892E+03);
  EXPECT_DOUBLE_EQ(r01.a_E_mps2.z(), -1.862645149231E-06);
}

TEST_F(RinexNavTest, Rinex2GlonassEqualsRinex3) {
  const Result<RinexNavFile> v2 = read_rinex_nav(write("v2.24g", kGlonassV2));
  const Result<RinexNavFile> v3 = read_rinex_nav(write("v3.nav", concat({kHeader, kGlonass})));
  ASSERT_TRUE(v2.ok()) << v2.error().to_string();
  ASSERT_TRUE(v3.ok());
  ASSERT_EQ(v2->nav.glonass.size(), 1u);
  const core::GlonassEphemeris& a = v2->nav.glonass[0];
  const core::GlonassEphemeris& b = v3->nav.glonass[0];
  EXPECT_EQ(a.sat, b.sat);
  EXPECT_EQ(a.toe, b.toe);
  EXPECT_EQ(a.frame_time, b.frame_time);
  EXPECT_EQ(a.p_E_m, b.p_E_m);
  EXPECT_EQ(a.frequency_channel, b.frequency_channel);
}

TEST_F(RinexNavTest, GzipInput) {
  const std::vector<std::string> lines = concat({kHeader, kGps, kGlonass, kBeidou});
  const Result<RinexNavFile> r = read_rinex_nav(write_gzip("mixed.nav.gz", lines));
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  EXPECT_EQ(r->nav.kepler.size(), 2u);
  EXPECT_EQ(r->nav.glonass.size(), 1u);
}

struct BadCase {
  std::string name;
  std::vector<std::string> lines;
  int line;
  std::string message;
};

TEST_F(RinexNavTest, MalformedInputsNameFileAndLine) {
  const int h = static_cast<int>(kHeader.size());
  std::vector<std::string> non_numeric = concat({kHeader, kGps});
  non_numeric[h + 2].replace(30, 1, "x");
  std::vector<std::string> bad_sat = concat({kHeader, kGps, kGlonass});
  bad_sat[h + 8].replace(0, 3, "R9x");
  std::vector<std::string> bad_system = concat({kHeader, kGps});
  bad_system[h].replace(0, 3, "X05");
  std::vector<std::string> bad_prn = concat({kHeader, kGps});
  bad_prn[h].replace(0, 3, "G00");
  const std::vector<std::string> truncated_eof(kGps.begin(), kGps.begin() + 5);
  const std::vector<std::string> truncated_mid(kGps.begin(), kGps.begin() + 4);
  std::vector<std::string> obs_header = kHeader;
  obs_header[0] = "     3.04           OBSERVATION DATA    M: MIXED            RINEX VERSION / TYPE";
  std::vector<std::string> v4_header = kHeader;
  v4_header[0] = "     4.00           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE";
  std::vector<std::string> bad_epoch = concat({kHeader, kGps});
  bad_epoch[h].replace(9, 2, "13");

  const std::vector<BadCase> cases = {
      {"empty", {}, 0, "empty file"},
      {"no_end_of_header", std::vector<std::string>(kHeader.begin(), kHeader.end() - 1), h - 1,
       "missing END OF HEADER"},
      {"observation_file", obs_header, 1, "not a navigation file"},
      {"not_rinex", {"hello world"}, 1, "not a RINEX file"},
      {"version4", v4_header, 1, "unsupported RINEX version"},
      {"truncated_at_eof", concat({kHeader, truncated_eof}), h + 5, "truncated record"},
      {"truncated_before_next", concat({kHeader, truncated_mid, kGlonass}), h + 5, "truncated record"},
      {"non_numeric", non_numeric, h + 3, "non-numeric field"},
      {"bad_satellite", bad_sat, h + 9, "bad satellite number 'R9x'"},
      {"unknown_system", bad_system, h + 1, "bad satellite number 'X05'"},
      {"prn_zero", bad_prn, h + 1, "bad satellite number 'G00'"},
      {"bad_month", bad_epoch, h + 1, "invalid epoch"},
  };
  for (const BadCase& c : cases) {
    const std::string path = write(c.name + ".nav", c.lines);
    const Result<RinexNavFile> r = read_rinex_nav(path);
    ASSERT_FALSE(r.ok()) << c.name;
    EXPECT_EQ(r.error().file, path) << c.name;
    EXPECT_EQ(r.error().line, c.line) << c.name << ": " << r.error().to_string();
    EXPECT_NE(r.error().message.find(c.message), std::string::npos) << c.name << ": " << r.error().to_string();
  }
}

TEST_F(RinexNavTest, GzipCutShortIsAnError) {
  std::vector<std::string> lines = kHeader;
  for (int i = 0; i < 200; ++i) lines = concat({lines, kGps});
  const std::string path = write_gzip("full.nav.gz", lines);
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string cut = (dir_ / "cut.nav.gz").string();
  {
    std::ofstream out(cut, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  const Result<RinexNavFile> r = read_rinex_nav(cut);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().file, cut);
  EXPECT_GT(r.error().line, 0);
}

TEST_F(RinexNavTest, MissingFileAndGarbageDoNotCrash) {
  EXPECT_FALSE(read_rinex_nav((dir_ / "does_not_exist.nav").string()).ok());
  std::vector<std::string> garbage = kHeader;
  for (int i = 0; i < 50; ++i) garbage.emplace_back(static_cast<std::size_t>(i * 7 % 90), char('!' + i));
  EXPECT_FALSE(read_rinex_nav(write("garbage.nav", garbage)).ok());
  std::vector<std::string> short_lines = concat({kHeader, kGps});
  for (std::size_t i = kHeader.size() + 1; i < short_lines.size(); ++i) short_lines[i].resize(10);
  (void)read_rinex_nav(write("short.nav", short_lines));  // must simply not crash
}

// ---- Round trip ------------------------------------------------------------------------------------------------

void expect_near_rel(double a, double b, const std::string& what) {
  EXPECT_LE(std::abs(a - b), 1e-12 * std::abs(a) + 1e-300) << what << ": " << a << " vs " << b;
}

void expect_same(const core::NavigationData& a, const core::NavigationData& b) {
  ASSERT_EQ(a.kepler.size(), b.kepler.size());
  ASSERT_EQ(a.glonass.size(), b.glonass.size());
  for (std::size_t i = 0; i < a.kepler.size(); ++i) {
    const core::KeplerEphemeris &x = a.kepler[i], &y = b.kepler[i];
    const std::string s = x.sat.to_string();
    EXPECT_EQ(x.sat, y.sat);
    EXPECT_EQ(x.toc, y.toc) << s;
    EXPECT_EQ(x.toe, y.toe) << s;
    EXPECT_NEAR(x.transmission_time - y.transmission_time, 0.0, 1e-6) << s;
    const double* px[] = {&x.af0_s,           &x.af1_sps,    &x.af2_sps2,      &x.sqrt_a_sqrtm, &x.e,
                          &x.i0_rad,          &x.omega0_rad, &x.omega_rad,     &x.m0_rad,       &x.delta_n_radps,
                          &x.omega_dot_radps, &x.idot_radps, &x.cuc_rad,       &x.cus_rad,      &x.crc_m,
                          &x.crs_m,           &x.cic_rad,    &x.cis_rad,       &x.toe_sow_s,    &x.tgd_s[0],
                          &x.tgd_s[1],        &x.accuracy_m, &x.fit_interval_h};
    const double* py[] = {&y.af0_s,           &y.af1_sps,    &y.af2_sps2,      &y.sqrt_a_sqrtm, &y.e,
                          &y.i0_rad,          &y.omega0_rad, &y.omega_rad,     &y.m0_rad,       &y.delta_n_radps,
                          &y.omega_dot_radps, &y.idot_radps, &y.cuc_rad,       &y.cus_rad,      &y.crc_m,
                          &y.crs_m,           &y.cic_rad,    &y.cis_rad,       &y.toe_sow_s,    &y.tgd_s[0],
                          &y.tgd_s[1],        &y.accuracy_m, &y.fit_interval_h};
    for (std::size_t k = 0; k < std::size(px); ++k) expect_near_rel(*px[k], *py[k], s + " field " + std::to_string(k));
    EXPECT_EQ(x.iode, y.iode) << s;
    EXPECT_EQ(x.iodc, y.iodc) << s;
    EXPECT_EQ(x.health, y.health) << s;
    EXPECT_EQ(x.data_source, y.data_source) << s;
  }
  for (std::size_t i = 0; i < a.glonass.size(); ++i) {
    const core::GlonassEphemeris &x = a.glonass[i], &y = b.glonass[i];
    const std::string s = x.sat.to_string();
    EXPECT_EQ(x.sat, y.sat);
    EXPECT_EQ(x.toe, y.toe) << s;
    EXPECT_EQ(x.frame_time, y.frame_time) << s;
    for (int k = 0; k < 3; ++k) {
      expect_near_rel(x.p_E_m[k], y.p_E_m[k], s + " p");
      expect_near_rel(x.v_E_mps[k], y.v_E_mps[k], s + " v");
      expect_near_rel(x.a_E_mps2[k], y.a_E_mps2[k], s + " a");
    }
    expect_near_rel(x.tau_n_s, y.tau_n_s, s + " tau");
    expect_near_rel(x.gamma_n, y.gamma_n, s + " gamma");
    EXPECT_EQ(x.frequency_channel, y.frequency_channel) << s;
    EXPECT_EQ(x.health, y.health) << s;
    EXPECT_EQ(x.age_days, y.age_days) << s;
  }
  ASSERT_EQ(a.gps_klobuchar.has_value(), b.gps_klobuchar.has_value());
  if (a.gps_klobuchar) {
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(a.gps_klobuchar->alpha[k], b.gps_klobuchar->alpha[k], 1e-4 * std::abs(a.gps_klobuchar->alpha[k]));
      EXPECT_NEAR(a.gps_klobuchar->beta[k], b.gps_klobuchar->beta[k], 1e-4 * std::abs(a.gps_klobuchar->beta[k]));
    }
  }
}

TEST_F(RinexNavTest, WriteReadRoundTripAllSystems) {
  const Result<RinexNavFile> first =
      read_rinex_nav(write("mixed.nav", concat({kHeader, kGps, kGlonass, kBeidou, kGalileo, kQzss})));
  ASSERT_TRUE(first.ok());
  const std::string out = (dir_ / "written.nav").string();
  ASSERT_TRUE(write_rinex_nav(out, first->nav).ok());
  const Result<RinexNavFile> second = read_rinex_nav(out);
  ASSERT_TRUE(second.ok()) << second.error().to_string();
  expect_same(first->nav, second->nav);
}

// ---- Shared datasets ---------------------------------------------------------------------------------------------

struct NavFileCounts {
  std::string path;
  std::map<Constellation, int> counts;
};

TEST_F(RinexNavTest, SharedNavFilesCountsAndRoundTrip) {
  const fs::path shared = CANYON_SHARED_DATA_DIR;
  if (!fs::exists(shared)) GTEST_SKIP() << "shared datasets not found at " << shared << " (CANYON_SHARED_DATA_DIR)";
  using C = Constellation;
  const std::vector<NavFileCounts> files = {
      {"matrtklib-static/base.nav", {{C::Gps, 13}, {C::Galileo, 67}, {C::Glonass, 19}, {C::BeiDou, 32}, {C::Qzss, 3}}},
      {"cssrlib-kinematic-doy265/SEPT2650.21P", {{C::Gps, 49}, {C::Galileo, 253}, {C::Qzss, 19}}},
      {"cssrlib-static-doy078/SEPT078M.21P", {{C::Gps, 24}, {C::Galileo, 210}, {C::Qzss, 8}}},
      {"rtklib-test-gsi-2005/07590920.05n", {{C::Gps, 162}}},
      {"rtklib-test-gsi-2005/30400920.05n", {{C::Gps, 164}}},
      {"m8p-galway-20181004/rinex/20181004_base-20181004-1452.nav", {{C::Gps, 16}, {C::Glonass, 31}, {C::Qzss, 2}}},
      {"m8p-galway-20181004/rinex/20181004_rover-20181004-1532.nav", {{C::Gps, 12}, {C::Glonass, 10}}},
      {"instinct-spirent-rtk-sim/RINEX_GN_Spirent.23N", {{C::Gps, 31}}},
      {"instinct-spirent-rtk-sim/RINEX_EN_Spirent.23L", {{C::Galileo, 26}}},
  };
  for (const NavFileCounts& f : files) {
    const Result<RinexNavFile> r = read_rinex_nav((shared / f.path).string());
    ASSERT_TRUE(r.ok()) << r.error().to_string();
    EXPECT_EQ(counts(r->nav), f.counts) << f.path;
    EXPECT_TRUE(r->warnings.empty()) << f.path;
    const std::string out = (dir_ / "roundtrip.nav").string();
    ASSERT_TRUE(write_rinex_nav(out, r->nav).ok());
    const Result<RinexNavFile> again = read_rinex_nav(out);
    ASSERT_TRUE(again.ok()) << f.path << ": " << again.error().to_string();
    SCOPED_TRACE(f.path);
    expect_same(r->nav, again->nav);
  }
}

}  // namespace
}  // namespace canyon::io
