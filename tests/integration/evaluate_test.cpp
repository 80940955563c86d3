// `canyon evaluate` as a real process: a hand-made RTKLIB file with injected errors scored to the hand-computed
// figures, RTKLIB's output forms produced by rnx2rtkp read to the same positions, the command's errors and exit
// codes, and the whole chain simulate -> process / rnx2rtkp -> evaluate with its table, Markdown, JSON and SVGs.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/io/pos_file.hpp"

#include "test_support.hpp"

namespace canyon {
namespace {

namespace fs = std::filesystem;

constexpr double kRoundingTolM = 5e-4;  // dms seconds (5 decimals) and heights (4 decimals) of the written file

test::CommandResult canyon(const std::string& args) {
  return test::run_command(std::string(CANYON_BINARY) + " " + args);
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The number after `"key": ` in `json` from position `from` on (NaN if absent).
double json_value(const std::string& json, const std::string& key, std::size_t from = 0) {
  const std::string tag = "\"" + key + "\": ";
  const std::size_t pos = json.find(tag, from);
  if (pos == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + pos + tag.size(), nullptr);
}

// ---- A hand-made RTKLIB file with injected errors -----------------------------------------------------------------

const core::Geodetic kStart{48.78 * core::kDegToRad, 9.18 * core::kDegToRad, 300.0};
const core::GpsTime kT0{2244, 36000.0};

Eigen::Vector3d truth_at(int k) {
  return core::geodetic_to_ecef(kStart) + core::enu_to_ecef({1.5 * k, 0.5 * k, 0.0}, kStart);
}

/// canyon's truth.csv: 10 epochs at 1 Hz.
fs::path write_truth(const fs::path& dir) {
  fs::path path = dir / "truth.csv";
  std::ofstream out(path);
  out << "gps_week,gps_tow_s,x,y,z,qx,qy,qz,qw\n";
  for (int k = 0; k < 10; ++k) {
    const Eigen::Vector3d p = truth_at(k);
    char line[160];
    std::snprintf(line, sizeof line, "%d,%.3f,%.4f,%.4f,%.4f,0,0,0,1\n", kT0.week, kT0.tow_s + k, p.x(), p.y(), p.z());
    out << line;
  }
  return path;
}

/// "ddd mm ss.sssss" as RTKLIB writes it (out-degform=dms), sign on the degrees.
std::string dms(double deg) {
  const double a = std::abs(deg);
  double d = std::floor(a);
  double m = std::floor((a - d) * 60.0);
  double s = (a - d - m / 60.0) * 3600.0;
  if (std::round(s * 1e5) >= 60.0 * 1e5) {
    s = 0.0;
    m += 1.0;
  }
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%s%3.0f %02.0f %08.5f", deg < 0 ? "-" : "", d, m, s);
  return buffer;
}

struct Injected {
  int q;
  Eigen::Vector3d d_N_m;
};
// 3D errors 0.5 (float), 0.02, 0.05, 0.5 (a wrong fix), 0, 5 (single), then 0.01 four times; horizontal 0, 0.02,
// 0.03, 0.5, 0, 3, 0.01, 0.01, 0 (vertical), 0.01.
const Injected kInjected[10] = {{2, {0, 0, 0.5}},   {1, {0.02, 0, 0}}, {1, {0, 0.03, 0.04}}, {1, {0.3, 0.4, 0}},
                                {1, {0, 0, 0}},     {5, {3, 0, 4}},    {1, {0.01, 0, 0}},    {1, {0, 0.01, 0}},
                                {1, {0, 0, -0.01}}, {1, {-0.01, 0, 0}}};

/// RTKLIB's exact layout with out-timesys=utc, out-timeform=hms, out-degform=dms.
fs::path write_rtklib_pos(const fs::path& dir) {
  fs::path path = dir / "rtklib_injected.pos";
  std::ofstream out(path);
  out << "% program   : RTKLIB ver.2.4.3\n% inp file  : rover.obs\n% pos mode  : Kinematic\n%\n"
         "% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)\n"
         "%  UTC                     latitude(d'\")   longitude(d'\")  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  "
         "sdne(m)  sdeu(m)  sdue(m) age(s)  ratio\n";
  const core::LeapSecondTable leaps = core::builtin_leap_seconds();
  for (int k = 0; k < 10; ++k) {
    const Eigen::Vector3d p_truth = truth_at(k);
    const core::Geodetic g_truth = core::ecef_to_geodetic(p_truth);
    const core::Geodetic g = core::ecef_to_geodetic(p_truth + core::enu_to_ecef(kInjected[k].d_N_m, g_truth));
    const core::CalendarTime utc = core::gps_to_utc(kT0 + k, leaps);
    char line[256];
    std::snprintf(line, sizeof line,
                  "%04d/%02d/%02d %02d:%02d:%06.3f %s %s %10.4f %3d %3d %8.4f %8.4f %8.4f %8.4f %8.4f %8.4f %6.2f "
                  "%6.1f\n",
                  utc.year, utc.month, utc.day, utc.hour, utc.minute, utc.second,
                  dms(g.lat_rad * core::kRadToDeg).c_str(), dms(g.lon_rad * core::kRadToDeg).c_str(), g.height_m,
                  kInjected[k].q, 9, 0.01, 0.01, 0.02, 0.0, 0.0, 0.0, 1.0, 3.5);
    out << line;
  }
  return path;
}

TEST(EvaluateCli, RtklibFileWithInjectedErrorsGivesTheHandComputedFigures) {
  const fs::path dir = test::temp_dir("evaluate_injected");
  const fs::path truth = write_truth(dir);
  const fs::path pos = write_rtklib_pos(dir);
  const auto r = canyon("evaluate --truth " + truth.string() + " --solution " + pos.string() +
                        " --label RTKLIB --epochs 12 --json " + (dir / "e.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("rover epochs: 12 (given)"), std::string::npos) << r.output;
  const std::string json = read_text(dir / "e.json");
  EXPECT_EQ(json_value(json, "solved"), 10);
  EXPECT_NEAR(json_value(json, "availability"), 10.0 / 12.0, 1e-9);
  const std::size_t status = json.find("\"status\"");
  EXPECT_NEAR(json_value(json, "rate", json.find("\"fixed\"", status)), 8.0 / 12.0, 1e-9);
  EXPECT_NEAR(json_value(json, "rate", json.find("\"float\"", status)), 1.0 / 12.0, 1e-9);
  EXPECT_NEAR(json_value(json, "rate", json.find("\"single\"", status)), 1.0 / 12.0, 1e-9);
  EXPECT_EQ(json_value(json, "wrong_fixes"), 1);
  EXPECT_NEAR(json_value(json, "wrong_fix_rate"), 1.0 / 8.0, 1e-9);
  EXPECT_EQ(json_value(json, "epochs_without_truth"), 0);
  EXPECT_DOUBLE_EQ(json_value(json, "time_to_first_fix_s"), 1.0);  // from the first record (no rover file)

  // Fixed, 3D: 0.02, 0.05, 0.5, 0, 0.01 x 4 -> sorted 0, .01, .01, .01, .01, .02, .05, .5
  const std::size_t fixed = json.find("\"fixed\": {\"epochs\": 8, \"3d\"");
  ASSERT_NE(fixed, std::string::npos) << json;
  const double mean_3d = (0.02 + 0.05 + 0.5 + 0.04) / 8.0;
  const double ms_3d = (0.0004 + 0.0025 + 0.25 + 4 * 0.0001) / 8.0;
  EXPECT_NEAR(json_value(json, "rmse_m", fixed), std::sqrt(ms_3d), kRoundingTolM);
  EXPECT_NEAR(json_value(json, "mean_m", fixed), mean_3d, kRoundingTolM);
  EXPECT_NEAR(json_value(json, "median_m", fixed), 0.01, kRoundingTolM);
  EXPECT_NEAR(json_value(json, "std_m", fixed), std::sqrt(ms_3d - mean_3d * mean_3d), kRoundingTolM);
  EXPECT_NEAR(json_value(json, "max_m", fixed), 0.5, kRoundingTolM);
  EXPECT_NEAR(json_value(json, "p95_m", fixed), 0.05 + 0.65 * (0.5 - 0.05), kRoundingTolM);  // rank 6.65
  // Fixed, horizontal: 0.02, 0.03, 0.5, 0, 0.01, 0.01, 0, 0.01 -> sorted 0, 0, .01, .01, .01, .02, .03, .5
  const std::size_t horizontal = json.find("\"horizontal\"", fixed);
  const double mean_h = (0.02 + 0.03 + 0.5 + 0.03) / 8.0;
  const double ms_h = (0.0004 + 0.0009 + 0.25 + 3 * 0.0001) / 8.0;
  EXPECT_NEAR(json_value(json, "rmse_m", horizontal), std::sqrt(ms_h), kRoundingTolM);
  EXPECT_NEAR(json_value(json, "mean_m", horizontal), mean_h, kRoundingTolM);
  EXPECT_NEAR(json_value(json, "median_m", horizontal), 0.01, kRoundingTolM);
  EXPECT_NEAR(json_value(json, "std_m", horizontal), std::sqrt(ms_h - mean_h * mean_h), kRoundingTolM);
  EXPECT_NEAR(json_value(json, "max_m", horizontal), 0.5, kRoundingTolM);
  EXPECT_NEAR(json_value(json, "p95_m", horizontal), 0.03 + 0.65 * (0.5 - 0.03), kRoundingTolM);
  // All ten epochs: 3D max 5 (the single epoch), 3D median of 0, .01 x 4, .02, .05, .5, .5, 5 = (0.01 + 0.02) / 2.
  const std::size_t all = json.find("\"all\": {\"epochs\": 10");
  ASSERT_NE(all, std::string::npos) << json;
  EXPECT_NEAR(json_value(json, "max_m", all), 5.0, kRoundingTolM);
  EXPECT_NEAR(json_value(json, "median_m", all), 0.015, kRoundingTolM);
}

// ---- RTKLIB's output forms, produced by rnx2rtkp ------------------------------------------------------------------

TEST(EvaluateCli, EveryRtklibOutputFormReadsToTheSamePositions) {
  const fs::path data = test::shared_data() / "cssrlib-static-doy078";
  if (!fs::exists(data)) GTEST_SKIP() << "shared dataset not present: " << data;
  if (!test::have_rtklib()) GTEST_SKIP() << "rnx2rtkp not installed";
  const fs::path dir = test::temp_dir("evaluate_rtklib_forms");
  const std::string conf = (data / "rtklib/rtk_kinematic.conf").string();
  const auto run = [&](const std::string& name, const std::vector<std::string>& options) {
    const fs::path extra = dir / (name + ".conf");
    std::ofstream(extra) << read_text(conf);
    std::ofstream(extra, std::ios::app) << "\n";
    for (const std::string& o : options) std::ofstream(extra, std::ios::app) << o << "\n";
    fs::path pos = dir / (name + ".pos");
    const auto r = test::run_command("cd " + data.string() + " && rnx2rtkp -k " + extra.string() + " -o " +
                                     pos.string() + " SEPT078M1.21O 3034078M1.21O SEPT078M.21P");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return pos;
  };
  const auto reference = io::read_pos_file(run("reference", {}).string());
  ASSERT_TRUE(reference.ok()) << reference.error().to_string();
  ASSERT_EQ(reference->size(), 60u);
  const std::vector<std::pair<std::string, std::vector<std::string>>> forms = {
      {"hms", {"out-timeform=hms"}},
      {"utc_hms", {"out-timesys=utc", "out-timeform=hms"}},
      {"utc_tow", {"out-timesys=utc"}},
      {"jst_hms_6dec", {"out-timesys=jst", "out-timeform=hms", "out-timendec=6"}},
      {"dms", {"out-degform=dms"}},
      {"xyz", {"out-solformat=xyz"}},
      {"enu", {"out-solformat=enu"}},
      {"enu_dms_jst", {"out-solformat=enu", "out-degform=dms", "out-timesys=jst"}},
      {"comma", {"out-fieldsep=,"}},
      {"semicolon_dms_hms", {"out-fieldsep=;", "out-degform=dms", "out-timeform=hms"}},
      {"bar_xyz_utc", {"out-fieldsep=|", "out-solformat=xyz", "out-timesys=utc"}},
      {"velocity", {"out-outvel=on"}},
      {"no_header", {"out-outhead=off"}},
  };
  for (const auto& [name, options] : forms) {
    SCOPED_TRACE(name);
    const auto read = io::read_pos_file(run(name, options).string());
    ASSERT_TRUE(read.ok()) << read.error().to_string();
    ASSERT_EQ(read->size(), reference->size());
    double max_m = 0.0;
    double max_dt_s = 0.0;
    for (std::size_t i = 0; i < read->size(); ++i) {
      max_m = std::max(max_m, ((*read)[i].p_E_m - (*reference)[i].p_E_m).norm());
      max_dt_s = std::max(max_dt_s, std::abs((*read)[i].time - (*reference)[i].time));
      EXPECT_EQ((*read)[i].status, (*reference)[i].status);
    }
    EXPECT_LT(max_m, 0.001);
    // RTKLIB's times are the receiver's (12:00:00.000461 here): the reference prints them to the millisecond.
    EXPECT_LE(max_dt_s, 0.0005 + 1e-9);
  }
  // Heights above the geoid cannot be read: a clear error naming the header line.
  const fs::path geoid = run("geoid", {"out-height=geodetic"});
  const auto r = canyon("evaluate --truth ecef:-3962108.673,3381309.574,3668678.638 --solution " + geoid.string() +
                        " --json " + (dir / "x.json").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find(geoid.string() + ":"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("out-height=geodetic"), std::string::npos) << r.output;
  // The ENU form through the command: the README's RTKLIB figures (60 fixed, 3D RMSE 3 mm).
  const auto enu = canyon("evaluate --truth ecef:-3962108.673,3381309.574,3668678.638 --solution " +
                          (dir / "enu.pos").string() + " --json " + (dir / "enu.json").string());
  ASSERT_EQ(enu.exit_code, 0) << enu.output;
  const std::string json = read_text(dir / "enu.json");
  EXPECT_NE(json.find("\"fixed\": {\"epochs\": 60, \"rate\": 1}"), std::string::npos) << json;
  EXPECT_NEAR(json_value(json, "rmse_m", json.find("\"all\"")), 0.003, 0.0005);
}

// ---- Errors -------------------------------------------------------------------------------------------------------

TEST(EvaluateCli, BadInputAndCommandLinesAreNamed) {
  const fs::path dir = test::temp_dir("evaluate_errors");
  const std::string truth = write_truth(dir).string();
  const std::string pos = write_rtklib_pos(dir).string();
  const std::string out = " --json " + (dir / "x.json").string();
  struct Case {
    const char* name;
    std::string args;
    int exit_code;
    std::string message;
  };
  const fs::path bad_pos = dir / "bad.pos";
  std::ofstream(bad_pos) << "% header\n2244 36000.000 48.78 9.18 300.0 1 9\n2244 36001.000 48.78 nine 300.0 1 9\n";
  const fs::path late = dir / "late.pos";
  std::ofstream(late) << "2244 40000.000 48.78 9.18 300.0 1 9\n";
  const fs::path bad_city = dir / "city.geojson";
  std::ofstream(bad_city) << "{\"type\":\"FeatureCollection\",\n\"features\":[{\"type\":\"Feature\"}]}\n";
  const fs::path enu = dir / "enu.pos";
  std::ofstream(enu) << "%  GPST          e-baseline(m)  n-baseline(m)  u-baseline(m)   Q  ns\n"
                        "2244 36000.000      5100.2152      1404.2535        17.0194   1  17\n";
  const Case cases[] = {
      {"missing truth", "--truth /nonexistent/truth.csv --solution " + pos + out, 1, "/nonexistent/truth.csv"},
      {"missing solution", "--truth " + truth + " --solution /nonexistent/a.pos" + out, 1, "/nonexistent/a.pos"},
      {"unreadable line", "--truth " + truth + " --solution " + bad_pos.string() + out, 1,
       bad_pos.string() + ":3: bad position fields"},
      {"label count", "--truth " + truth + " --solution " + pos + " --solution " + pos + " --label A" + out, 2,
       "1 labels for 2 solutions"},
      {"epochs and rover", "--truth " + truth + " --solution " + pos + " --epochs 10 --rover r.obs" + out, 2,
       "excludes"},
      {"no truth", "--solution " + pos + out, 2, "--truth is required"},
      {"bad truth spec", "--truth ecef:1,2 --solution " + pos + out, 1, "expected 3 comma-separated numbers"},
      {"no overlap", "--truth " + truth + " --solution " + late.string() + out, 1,
       late.string() + ": no solved epoch has truth"},
      {"broken city", "--truth " + truth + " --solution " + pos + " --city " + bad_city.string() + out, 1,
       bad_city.string() + ":2: feature without a geometry object"},
      {"enu without base", "--truth " + truth + " --solution " + enu.string() + out, 1,
       enu.string() + ":2: e/n/u baseline solution (RTKLIB out-solformat=enu) without a '% ref pos' header line"},
      {"fewer epochs than solved", "--truth " + truth + " --solution " + pos + " --epochs 5" + out, 1,
       "10 solved epochs, but only 5 rover epochs"},
      {"unwritable output", "--truth " + truth + " --solution " + pos + " --out-dir /proc/canyon-cannot-create", 1,
       "/proc/canyon-cannot-create/evaluation.md"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const auto r = canyon("evaluate " + c.args);
    EXPECT_EQ(r.exit_code, c.exit_code) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
  }
  // Help documents the epoch rule and the exit codes.
  const auto help = canyon("evaluate --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("Rover epochs (every rate's denominator)"), std::string::npos) << help.output;
  EXPECT_NE(help.output.find("Exit status: 0 success, 1 bad input"), std::string::npos) << help.output;
}

TEST(EvaluateCli, TruthGapsAreCountedAsEpochsWithoutTruth) {
  const fs::path dir = test::temp_dir("evaluate_gap");
  std::string truth_text = read_text(write_truth(dir));
  // Drop the truth rows of epochs 4, 5 and 6: a 4 s gap, longer than the 2 s interpolation limit.
  std::istringstream in(truth_text);
  std::ofstream gapped(dir / "gapped.csv");
  int row = -1;
  for (std::string line; std::getline(in, line); ++row) {
    if (row < 4 || row > 6) gapped << line << "\n";
  }
  gapped.close();
  const auto r = canyon("evaluate --truth " + (dir / "gapped.csv").string() + " --solution " +
                        write_rtklib_pos(dir).string() + " --json " + (dir / "g.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("3 of 10 solved epochs have no truth"), std::string::npos) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("\nepochs without truth +3\n"))) << r.output;
  // Rover epochs: 7 truth epochs joined with the solution's 10.
  EXPECT_NE(r.output.find("rover epochs: 10 (truth epochs"), std::string::npos) << r.output;
  EXPECT_EQ(json_value(read_text(dir / "g.json"), "epochs_with_truth"), 7);
}

// ---- The whole chain ----------------------------------------------------------------------------------------------

TEST(EvaluateCli, SimulateProcessRtklibEvaluate) {
  if (!test::have_rtklib()) GTEST_SKIP() << "rnx2rtkp not installed";
  ASSERT_EQ(test::run_command("command -v xmllint").exit_code, 0)
      << "xmllint missing: scripts/setup.sh installs libxml2-utils";
  const fs::path dir = test::temp_dir("evaluate_chain");
  fs::remove_all(dir);
  const fs::path sim = dir / "sim";
  auto r = canyon("simulate -q --scenario open-sky --duration 60 --out " + sim.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = canyon("process -q --mode rtk --rover " + (sim / "rover.obs").string() + " --base " +
             (sim / "base.obs").string() + " --nav " + (sim / "nav.rnx").string() + " --out " +
             (dir / "canyon.pos").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string conf = std::string(CANYON_SOURCE_DIR) + "/config/rtklib/sim.conf";
  r = test::run_command("rnx2rtkp -k " + conf + " -o " + (dir / "rtklib.pos").string() + " " +
                        (sim / "rover.obs").string() + " " + (sim / "base.obs").string() + " " +
                        (sim / "nav.rnx").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string solutions = " --solution " + (dir / "rtklib.pos").string() + " --label RTKLIB --solution " +
                                (dir / "canyon.pos").string() + " --label canyon";
  r = canyon("evaluate --truth " + (sim / "truth.csv").string() + solutions + " --city " +
             (sim / "city.geojson").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::cout << r.output;
  EXPECT_NE(r.output.find("rover epochs: 301 (truth epochs"), std::string::npos) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex(" +RTKLIB :  +canyon\nepochs +301 : +301\n"))) << r.output;
  // Default output folder: evaluation/ beside the first solution.
  const fs::path out = dir / "evaluation";
  for (const char* name : {"evaluation.md", "evaluation.json", "trajectory.svg", "ape.svg"}) {
    EXPECT_TRUE(fs::exists(out / name) && fs::file_size(out / name) > 0) << name;
    EXPECT_NE(r.output.find("canyon evaluate: wrote " + (out / name).string()), std::string::npos) << name;
  }
  for (const char* svg : {"trajectory.svg", "ape.svg"}) {
    const auto lint = test::run_command("xmllint --noout " + (out / svg).string());
    EXPECT_EQ(lint.exit_code, 0) << svg << ": " << lint.output;
  }
  EXPECT_NE(read_text(out / "evaluation.md").find("| | RTKLIB | canyon |"), std::string::npos);
  const std::string json = read_text(out / "evaluation.json");
  EXPECT_NE(json.find("\"epochs\": {\"count\": 301, \"source\": \"truth+solutions\"}"), std::string::npos) << json;
  EXPECT_NE(json.find("\"label\": \"RTKLIB\""), std::string::npos);
  EXPECT_NE(json.find("\"label\": \"canyon\""), std::string::npos);
  // RTKLIB fixes open sky (tests/integration/simulate_test.cpp asserts the same on 3 minutes).
  EXPECT_GE(json_value(json, "rate", json.find("\"fixed\"", json.find("\"status\""))), 0.9);

  // The rover file gives the same epochs; --markdown/--json alone write only those.
  r = canyon("evaluate -q --truth " + (sim / "truth.csv").string() + solutions + " --rover " +
             (sim / "rover.obs").string() + " --json " + (dir / "rover.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(read_text(dir / "rover.json").find("\"epochs\": {\"count\": 301, \"source\": \"rover-file\"}"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "trajectory.svg"));
}

}  // namespace
}  // namespace canyon
