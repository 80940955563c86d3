// read_pos_file on every form RTKLIB 2.4.3 writes. The records below are rnx2rtkp's own output (first and last
// epoch of cssrlib-static-doy078, RTK, with the out-* options named in each case), header lines as RTKLIB writes
// them: every form must give the same GPST times and ECEF positions as the plain GPST week/tow, decimal-degree one
// (within 1 mm: dms seconds have 5 decimals, 0.15 mm; ENU baselines and ECEF 4 decimals).

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/io/pos_file.hpp"

namespace canyon::io {
namespace {

namespace fs = std::filesystem;

constexpr double kMaxPositionDiffM = 0.001;
constexpr double kMaxTimeDiffS = 1e-6;

fs::path write_file(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / "canyon_pos_formats";
  fs::create_directories(dir);
  fs::path path = dir / name;
  std::ofstream(path) << text;
  return path;
}

const char* const kDegreesGpstTow = R"(% program   : RTKLIB ver.2.4.3
% ref pos   : 35.326681912  139.466071726    46.5007
%
% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  GPST          latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio
2149 475200.000   35.339325779  139.522173142    65.7120   1  17   0.0035   0.0028   0.0079  -0.0006   0.0015  -0.0031   0.00   16.8
2149 475259.000   35.339325772  139.522173125    65.7130   1  17   0.0018   0.0032   0.0079   0.0021   0.0011  -0.0032   0.00   27.6
)";

struct Variant {
  const char* name;
  const char* text;
};

const Variant kVariants[] = {
    {"calendar_gpst (out-timeform=hms)", R"(% ref pos   : 35.326681912  139.466071726    46.5007
% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio
2021/03/19 12:00:00.000   35.339325779  139.522173142    65.7120   1  17   0.0035   0.0028   0.0079  -0.0006   0.0015  -0.0031   0.00   16.8
2021/03/19 12:00:59.000   35.339325772  139.522173125    65.7130   1  17   0.0018   0.0032   0.0079   0.0021   0.0011  -0.0032   0.00   27.6
)"},
    {"calendar_utc (out-timesys=utc)", R"(% ref pos   : 35.326681912  139.466071726    46.5007
% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  UTC                   latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio
2021/03/19 11:59:42.000   35.339325779  139.522173142    65.7120   1  17   0.0035   0.0028   0.0079  -0.0006   0.0015  -0.0031   0.00   16.8
2021/03/19 12:00:41.000   35.339325772  139.522173125    65.7130   1  17   0.0018   0.0032   0.0079   0.0021   0.0011  -0.0032   0.00   27.6
)"},
    {"calendar_jst (out-timesys=jst)", R"(% ref pos   : 35.326681912  139.466071726    46.5007
% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  JST                   latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio
2021/03/19 20:59:42.000   35.339325779  139.522173142    65.7120   1  17   0.0035   0.0028   0.0079  -0.0006   0.0015  -0.0031   0.00   16.8
2021/03/19 21:00:41.000   35.339325772  139.522173125    65.7130   1  17   0.0018   0.0032   0.0079   0.0021   0.0011  -0.0032   0.00   27.6
)"},
    {"dms (out-degform=dms)", R"(% ref pos   : 35 19 36.05488  139 27 57.85821    46.5007
% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  GPST            latitude(d'")   longitude(d'")  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdue(m) age(s)  ratio
2149 475200.000   35 20 21.57280  139 31 19.82331    65.7120   1  17   0.0035   0.0028   0.0079  -0.0006   0.0015  -0.0031   0.00   16.8
2149 475259.000   35 20 21.57278  139 31 19.82325    65.7130   1  17   0.0018   0.0032   0.0079   0.0021   0.0011  -0.0032   0.00   27.6
)"},
    {"ecef (out-solformat=xyz)", R"(% ref pos   : -3959400.6310   3385704.5330   3667523.1110
% (x/y/z-ecef=WGS84,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  GPST              x-ecef(m)      y-ecef(m)      z-ecef(m)   Q  ns   sdx(m)   sdy(m)   sdz(m)  sdxy(m)  sdyz(m)  sdzx(m) age(s)  ratio
2149 475200.000  -3962108.6738   3381309.5729   3668678.6383   1  17   0.0061   0.0051   0.0044  -0.0048   0.0036  -0.0040   0.00   16.8
2149 475259.000  -3962108.6736   3381309.5749   3668678.6382   1  17   0.0058   0.0055   0.0037  -0.0046   0.0036  -0.0046   0.00   27.6
)"},
    {"ecef_utc_tow (out-solformat=xyz, out-timesys=utc: week/tow of the UTC instant)",
     R"(% ref pos   : -3959400.6310   3385704.5330   3667523.1110
% (x/y/z-ecef=WGS84,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  UTC               x-ecef(m)      y-ecef(m)      z-ecef(m)   Q  ns   sdx(m)   sdy(m)   sdz(m)  sdxy(m)  sdyz(m)  sdzx(m) age(s)  ratio
2149 475182.000  -3962108.6738   3381309.5729   3668678.6383   1  17   0.0061   0.0051   0.0044  -0.0048   0.0036  -0.0040   0.00   16.8
2149 475241.000  -3962108.6736   3381309.5749   3668678.6382   1  17   0.0058   0.0055   0.0037  -0.0046   0.0036  -0.0046   0.00   27.6
)"},
    {"enu (out-solformat=enu)", R"(% ref pos   : 35.326681912  139.466071726    46.5007
% (e/n/u-baseline=WGS84,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  GPST          e-baseline(m)  n-baseline(m)  u-baseline(m)   Q  ns   sde(m)   sdn(m)   sdu(m)  sden(m)  sdnu(m)  sdue(m) age(s)  ratio
2149 475200.000      5100.2152      1404.2535        17.0194   1  17   0.0028   0.0035   0.0079  -0.0006  -0.0031   0.0015   0.00   16.8
2149 475259.000      5100.2136      1404.2528        17.0203   1  17   0.0032   0.0018   0.0079   0.0021  -0.0032   0.0012   0.00   27.6
)"},
    {"enu_dms_ref (out-solformat=enu, out-degform=dms)", R"(% ref pos   : 35 19 36.05488  139 27 57.85821    46.5007
% (e/n/u-baseline=WGS84,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  GPST          e-baseline(m)  n-baseline(m)  u-baseline(m)   Q  ns   sde(m)   sdn(m)   sdu(m)  sden(m)  sdnu(m)  sdue(m) age(s)  ratio
2149 475200.000      5100.2152      1404.2535        17.0194   1  17   0.0028   0.0035   0.0079  -0.0006  -0.0031   0.0015   0.00   16.8
2149 475259.000      5100.2136      1404.2528        17.0203   1  17   0.0032   0.0018   0.0079   0.0021  -0.0032   0.0012   0.00   27.6
)"},
    {"enu_comma_utc (out-solformat=enu, out-fieldsep=',', out-timesys=utc)",
     R"(% ref pos   : 35.326681912, 139.466071726,   46.5007
% (e/n/u-baseline=WGS84,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  UTC         , e-baseline(m), n-baseline(m), u-baseline(m),  Q, ns,  sde(m),  sdn(m),  sdu(m), sden(m), sdnu(m), sdue(m),age(s), ratio
2149,475182.000,     5100.2152,     1404.2535,       17.0194,  1, 17,  0.0028,  0.0035,  0.0079, -0.0006, -0.0031,  0.0015,  0.00,  16.8
2149,475241.000,     5100.2136,     1404.2528,       17.0203,  1, 17,  0.0032,  0.0018,  0.0079,  0.0021, -0.0032,  0.0012,  0.00,  27.6
)"},
    {"degrees_comma (out-fieldsep=',')", R"(% ref pos   : 35.326681912, 139.466071726,   46.5007
% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  GPST        , latitude(deg),longitude(deg), height(m),  Q, ns,  sdn(m),  sde(m),  sdu(m), sdne(m), sdeu(m), sdun(m),age(s), ratio
2149,475200.000,  35.339325779, 139.522173142,   65.7120,  1, 17,  0.0035,  0.0028,  0.0079, -0.0006,  0.0015, -0.0031,  0.00,  16.8
2149,475259.000,  35.339325772, 139.522173125,   65.7130,  1, 17,  0.0018,  0.0032,  0.0079,  0.0021,  0.0011, -0.0032,  0.00,  27.6
)"},
    {"dms_semicolon_calendar (out-fieldsep=';', out-degform=dms, out-timeform=hms)",
     R"(% ref pos   : 35;19;36.05488; 139;27;57.85821;   46.5007
% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  GPST                ;   latitude(d'");  longitude(d'"); height(m);  Q; ns;  sdn(m);  sde(m);  sdu(m); sdne(m); sdeu(m); sdue(m);age(s); ratio
2021/03/19 12:00:00.000;  35;20;21.57280; 139;31;19.82331;   65.7120;  1; 17;  0.0035;  0.0028;  0.0079; -0.0006;  0.0015; -0.0031;  0.00;  16.8
2021/03/19 12:00:59.000;  35;20;21.57278; 139;31;19.82325;   65.7130;  1; 17;  0.0018;  0.0032;  0.0079;  0.0021;  0.0011; -0.0032;  0.00;  27.6
)"},
    {"ecef_bar_calendar_1dec (out-fieldsep='|', out-timeform=hms, out-timendec=1)",
     R"(% ref pos   : -3959400.6310|  3385704.5330|  3667523.1110
% (x/y/z-ecef=WGS84,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  GPST              |     x-ecef(m)|     y-ecef(m)|     z-ecef(m)|  Q| ns|  sdx(m)|  sdy(m)|  sdz(m)| sdxy(m)| sdyz(m)| sdzx(m)|age(s)| ratio
2021/03/19 12:00:00.0| -3962108.6738|  3381309.5729|  3668678.6383|  1| 17|  0.0061|  0.0051|  0.0044| -0.0048|  0.0036| -0.0040|  0.00|  16.8
2021/03/19 12:00:59.0| -3962108.6736|  3381309.5749|  3668678.6382|  1| 17|  0.0058|  0.0055|  0.0037| -0.0046|  0.0036| -0.0046|  0.00|  27.6
)"},
    {"dms_jst_tow_velocity (out-degform=dms, out-timesys=jst, out-outvel=on)",
     R"(% ref pos   : 35 19 36.05488  139 27 57.85821    46.5007
% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
%  JST             latitude(d'")   longitude(d'")  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdue(m) age(s)  ratio    vn(m/s)    ve(m/s)    vu(m/s)      sdvn     sdve     sdvu    sdvne    sdveu    sdvun
2149 507582.000   35 20 21.57280  139 31 19.82331    65.7120   1  17   0.0035   0.0028   0.0079  -0.0006   0.0015  -0.0031   0.00   16.8    0.00000    0.00000    0.00000   0.00000  0.00000  0.00000  0.00000  0.00000  0.00000
2149 507641.000   35 20 21.57278  139 31 19.82325    65.7130   1  17   0.0018   0.0032   0.0079   0.0021   0.0011  -0.0032   0.00   27.6    0.00000    0.00000    0.00000   0.00000  0.00000  0.00000  0.00000  0.00000  0.00000
)"},
};

TEST(PosFileFormats, EveryRtklibFormGivesTheSamePositionsAndTimes) {
  const auto reference = read_pos_file(write_file("reference.pos", kDegreesGpstTow).string());
  ASSERT_TRUE(reference.ok()) << reference.error().to_string();
  ASSERT_EQ(reference->size(), 2u);
  EXPECT_EQ(reference->front().time, (core::GpsTime{2149, 475200.0}));
  int k = 0;
  for (const Variant& v : kVariants) {
    SCOPED_TRACE(v.name);
    const auto read = read_pos_file(write_file("variant" + std::to_string(k++) + ".pos", v.text).string());
    ASSERT_TRUE(read.ok()) << read.error().to_string();
    ASSERT_EQ(read->size(), reference->size());
    for (std::size_t i = 0; i < read->size(); ++i) {
      const core::Solution& a = (*read)[i];
      const core::Solution& b = (*reference)[i];
      EXPECT_NEAR(a.time - b.time, 0.0, kMaxTimeDiffS) << "record " << i;
      EXPECT_LT((a.p_E_m - b.p_E_m).norm(), kMaxPositionDiffM) << "record " << i;
      EXPECT_EQ(a.status, b.status);
      EXPECT_EQ(a.num_satellites, b.num_satellites);
      EXPECT_DOUBLE_EQ(a.ratio, b.ratio);
      // The same covariance, whatever frame the file gave it in (4-decimal standard deviations).
      EXPECT_LT((a.P_E_m2 - b.P_E_m2).cwiseAbs().maxCoeff(), 2e-5) << "record " << i << "\n"
                                                                   << a.P_E_m2 << "\n"
                                                                   << b.P_E_m2;
    }
  }
}

TEST(PosFileFormats, DmsSignIsOnTheDegreesNegativeZeroIncluded) {
  // RTKLIB prints -0.5 deg as "-0 30 00.00000" (sign of the value on the degrees field).
  const auto read = read_pos_file(
      write_file("dms_south_west.pos", R"(%  GPST            latitude(d'")   longitude(d'")  height(m)   Q  ns
2149 475200.000   -0 30 00.00000  -58 15 36.00000    10.0000   5   8
)")
          .string());
  ASSERT_TRUE(read.ok()) << read.error().to_string();
  const core::Geodetic g = core::ecef_to_geodetic(read->front().p_E_m);
  EXPECT_NEAR(g.lat_rad * core::kRadToDeg, -0.5, 1e-9);
  EXPECT_NEAR(g.lon_rad * core::kRadToDeg, -58.26, 1e-9);
  EXPECT_NEAR(g.height_m, 10.0, 1e-6);
  EXPECT_EQ(read->front().status, core::SolutionStatus::Single);
}

TEST(PosFileFormats, UtcTimesUseTheLeapSecondsOfTheirDate) {
  // 2016-12-31 23:59:59 UTC is GPST - 17 s; 2017-01-01 00:00:00 UTC is GPST - 18 s.
  const auto read = read_pos_file(
      write_file("utc_leap.pos", R"(%  UTC                   latitude(deg) longitude(deg)  height(m)   Q  ns
2016/12/31 23:59:59.000   35.000000000  139.000000000    10.0000   5   8
2017/01/01 00:00:00.000   35.000000000  139.000000000    10.0000   5   8
)")
          .string());
  ASSERT_TRUE(read.ok()) << read.error().to_string();
  const core::GpsTime t0 = core::calendar_to_gps({2016, 12, 31, 23, 59, 59.0});
  EXPECT_NEAR((*read)[0].time - t0, 17.0, 1e-9);
  EXPECT_NEAR((*read)[1].time - t0, 1.0 + 18.0, 1e-9);
}

TEST(PosFileFormats, WithoutColumnTitlesPositionsAreGuessed) {
  const auto read =
      read_pos_file(write_file("no_titles.pos", R"(2149 475200.000   35.339325779  139.522173142    65.7120   1  17
2149 475201.000  -3962108.6738   3381309.5729   3668678.6383   1  17   0.0061   0.0051   0.0044  -0.0048   0.0036  -0.0040   0.00   16.8
)")
                        .string());
  ASSERT_TRUE(read.ok()) << read.error().to_string();
  ASSERT_EQ(read->size(), 2u);
  EXPECT_LT(((*read)[0].p_E_m - (*read)[1].p_E_m).norm(), 0.01);
}

struct BadCase {
  const char* name;
  const char* text;
  int line;
  const char* message;
};

TEST(PosFileFormats, UnreadableFormsAndRecordsNameTheLine) {
  const BadCase cases[] = {
      {"enu_without_ref_pos", R"(% (e/n/u-baseline=WGS84,Q=1:fix)
%  GPST          e-baseline(m)  n-baseline(m)  u-baseline(m)   Q  ns
2149 475200.000      5100.2152      1404.2535        17.0194   1  17
)",
       3, "without a '% ref pos' header line"},
      {"geoid_heights",
       R"(% (lat/lon/height=WGS84/geodetic,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)
2149 475200.000   35.339325779  139.522173142    28.1628   1  17
)",
       1, "out-height=geodetic"},
      {"nmea", "$GNGGA,115942.00,3520.3595467,N,13931.3303885,E,4,17,1.0,28.163,M,37.549,M,0.0,0000*62\n", 1, "NMEA"},
      {"bad_ref_pos", R"(% ref pos   : 35.3x  139.466071726    46.5007
%  GPST          e-baseline(m)  n-baseline(m)  u-baseline(m)   Q  ns
)",
       1, "bad base position"},
      {"bad_q", "%  GPST latitude(deg) longitude(deg) height(m) Q ns\n2149 475200.000 35.3 139.5 65.7 9 17\n", 2,
       "bad solution status Q '9'"},
      {"bad_minutes",
       "%  GPST latitude(d'\") longitude(d'\") height(m) Q ns\n2149 475200.000 35 61 1.0 139 31 1.0 65.7 1 17\n", 2,
       "bad latitude/longitude/height"},
      {"too_few_dms_fields",
       "%  GPST latitude(d'\") longitude(d'\") height(m) Q ns\n2149 475200.000 35.3 139.5 65.7 1 17\n", 2,
       "record has 7 fields, expected at least 11"},
      {"bad_sigma", "2149 475200.000 35.3 139.5 65.7 1 17 0.0035 x.0028\n", 1, "bad number 'x.0028'"},
      {"bad_date", "2021/13/19 12:00:00.000 35.3 139.5 65.7 1 17\n", 1, "bad date/time"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path path = write_file(std::string(c.name) + ".pos", c.text);
    const auto read = read_pos_file(path.string());
    ASSERT_FALSE(read.ok());
    EXPECT_EQ(read.error().file, path.string());
    EXPECT_EQ(read.error().line, c.line) << read.error().to_string();
    EXPECT_NE(read.error().message.find(c.message), std::string::npos) << read.error().to_string();
  }
}

}  // namespace
}  // namespace canyon::io
