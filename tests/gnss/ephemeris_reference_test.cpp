// Agreement of canyon's broadcast satellite positions and clocks with RTKLIB 2.4.3 on every shared dataset.
// Reference rows (tests/data/ephemeris_reference/*.csv) come from tests/gnss/make_ephemeris_reference.sh: RTKLIB's
// satposs trace (transmission time printed to 1 us, position to 1 mm, clock to 1 ps). Tolerances: 1 cm and 0.1 ns
// for Kepler orbits, 10 cm and 0.1 ns for GLONASS. The 1 us rounding of the printed time costs at most 2 mm.

#include <array>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "canyon/gnss/ephemeris.hpp"
#include "canyon/io/rinex_nav.hpp"

namespace canyon::gnss {
namespace {

constexpr double kMaxKeplerPosErrorM = 0.01;
constexpr double kMaxGlonassPosErrorM = 0.10;
constexpr double kMaxClockErrorNs = 0.1;

struct Dataset {
  std::string name;
  std::vector<std::string> navs;  // relative to CANYON_SHARED_DATA_DIR
};

const std::vector<Dataset>& datasets() {
  static const std::vector<Dataset> d = {
      {"gsi2005-0759", {"rtklib-test-gsi-2005/07590920.05n"}},
      {"gsi2005-3040", {"rtklib-test-gsi-2005/30400920.05n"}},
      {"cssrlib-static-doy078", {"cssrlib-static-doy078/SEPT078M.21P"}},
      {"cssrlib-kinematic-doy265", {"cssrlib-kinematic-doy265/SEPT2650.21P"}},
      {"matrtklib-static", {"matrtklib-static/base.nav"}},
      {"m8p-galway-20181004",
       {"m8p-galway-20181004/rinex/20181004_rover-20181004-1532.nav",
        "m8p-galway-20181004/rinex/20181004_base-20181004-1452.nav"}},
      {"instinct-spirent-rtk-sim", {"instinct-spirent-rtk-sim/RINEX_GN_Spirent.23N"}},
  };
  return d;
}

struct Row {
  core::SatelliteId sat;
  core::GpsTime t_tx;
  Eigen::Vector3d p_E_m;
  double clock_ns = 0.0;
};

std::vector<Row> read_reference(const std::string& path) {
  std::vector<Row> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream ss(line);
    std::string field;
    std::vector<std::string> f;
    while (std::getline(ss, field, ',')) f.push_back(field);
    if (f.size() < 7) continue;
    Row r;
    r.sat = core::parse_satellite(f[0]).value();
    r.t_tx = core::GpsTime{std::stoi(f[1]), std::stod(f[2])};
    r.p_E_m = Eigen::Vector3d(std::stod(f[3]), std::stod(f[4]), std::stod(f[5]));
    r.clock_ns = std::stod(f[6]);
    rows.push_back(r);
  }
  return rows;
}

class EphemerisReference : public ::testing::TestWithParam<Dataset> {};

TEST_P(EphemerisReference, MatchesRtklib) {
  const Dataset& ds = GetParam();
  const std::filesystem::path shared = CANYON_SHARED_DATA_DIR;
  if (!std::filesystem::exists(shared)) {
    GTEST_SKIP() << "shared datasets not found at " << shared << " (CANYON_SHARED_DATA_DIR)";
  }
  core::NavigationData nav;
  for (const std::string& n : ds.navs) {
    const Result<io::RinexNavFile> file = io::read_rinex_nav((shared / n).string());
    ASSERT_TRUE(file.ok()) << file.error().to_string();
    nav.merge(file->nav);
  }
  EphemerisOptions options;
  options.use_unhealthy = true;  // RTKLIB computes unhealthy satellites too (and excludes them later)
  const EphemerisStore store(std::move(nav), options);
  const std::vector<Row> rows =
      read_reference(std::string(CANYON_TEST_DATA_DIR) + "/ephemeris_reference/" + ds.name + ".csv");
  ASSERT_FALSE(rows.empty());

  struct Max {
    double pos_m = 0.0, clock_ns = 0.0;
    int n = 0;
  };
  std::map<core::Constellation, Max> max;
  for (const Row& r : rows) {
    const std::optional<SatelliteState> s = store.state(r.sat, r.t_tx);
    ASSERT_TRUE(s.has_value()) << ds.name << " " << r.sat.to_string() << " no ephemeris at " << r.t_tx.week << " "
                               << r.t_tx.tow_s;
    const double dpos_m = (s->p_E_m - r.p_E_m).norm();
    const double dclk_ns = std::abs(s->clock_bias_s * 1e9 - r.clock_ns);
    Max& m = max[r.sat.system];
    m.pos_m = std::max(m.pos_m, dpos_m);
    m.clock_ns = std::max(m.clock_ns, dclk_ns);
    ++m.n;
    const double tol_m = r.sat.system == core::Constellation::Glonass ? kMaxGlonassPosErrorM : kMaxKeplerPosErrorM;
    EXPECT_LT(dpos_m, tol_m) << ds.name << " " << r.sat.to_string() << " tow " << std::setprecision(12) << r.t_tx.tow_s;
    EXPECT_LT(dclk_ns, kMaxClockErrorNs) << ds.name << " " << r.sat.to_string() << " tow " << r.t_tx.tow_s;
  }
  for (const auto& [system, m] : max) {
    std::ostringstream text;
    text << std::fixed << std::setprecision(4) << ds.name << " " << core::constellation_name(system) << ": " << m.n
         << " rows, max |dpos| " << m.pos_m << " m, max |dclock| " << m.clock_ns << " ns";
    std::cout << text.str() << "\n";
    RecordProperty(std::string(core::constellation_name(system)) + "_max_pos_m", std::to_string(m.pos_m));
    RecordProperty(std::string(core::constellation_name(system)) + "_max_clock_ns", std::to_string(m.clock_ns));
  }
}

INSTANTIATE_TEST_SUITE_P(AllDatasets, EphemerisReference, ::testing::ValuesIn(datasets()),
                         [](const ::testing::TestParamInfo<Dataset>& info) {
                           std::string n = info.param.name;
                           for (char& c : n) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return n;
                         });

}  // namespace
}  // namespace canyon::gnss
