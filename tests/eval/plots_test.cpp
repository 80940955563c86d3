// The SVG writer, the city GeoJSON reader and the plots: well-formed XML (checked with xmllint; skipped, saying so,
// without it), escaping, ticks, one panel per solution, points outside the frame counted, errors with file and line.

#include "canyon/eval/plots.hpp"

#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "canyon/core/constants.hpp"
#include "canyon/core/geodesy.hpp"
#include "canyon/eval/city_map.hpp"
#include "canyon/eval/svg.hpp"

#include "integration/test_support.hpp"

namespace canyon::eval {
namespace {

namespace fs = std::filesystem;

fs::path write_file(const std::string& name, const std::string& text) {
  const fs::path dir = test::temp_dir("eval_plots");
  std::ofstream(dir / name) << text;
  return dir / name;
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

/// xmllint's verdict on `svg`: empty if well-formed; nullopt if xmllint is not installed, and the test then skips
/// with kNoXmllint after its other checks.
std::optional<std::string> xml_problems(const SvgDocument& svg, const std::string& name) {
  if (test::run_command("command -v xmllint").exit_code != 0) return std::nullopt;
  const fs::path path = test::temp_dir("eval_plots") / name;
  EXPECT_TRUE(svg.write(path.string()).ok());
  const auto r = test::run_command("xmllint --noout " + path.string());
  return r.exit_code == 0 ? std::string() : r.output;
}
constexpr const char* kNoXmllint =
    "xmllint not installed (scripts/setup.sh installs libxml2-utils): the SVG was not checked for well-formed XML";

TEST(Svg, EscapesTextAndFormatsNumbers) {
  EXPECT_EQ(xml_escape("a<b & \"c\" 'd'>"), "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;");
  EXPECT_EQ(xml_escape(std::string("bell\a")), "bell");
  EXPECT_EQ(svg_number(12.5), "12.5");
  EXPECT_EQ(svg_number(3.0), "3");
  EXPECT_EQ(svg_number(-0.001), "0");
  EXPECT_EQ(svg_number(-0.25), "-0.25");
  EXPECT_EQ(svg_number(1.23456, 3), "1.235");
}

TEST(Svg, DocumentIsWellFormed) {
  SvgDocument svg(200, 100);
  svg.define_clip("c1", 10, 10, 50, 50);
  svg.begin_group("c1");
  svg.circle(20, 20, 3, {"#2ca02c", "#1e6e1e", 0.5, 1.0, {}});
  svg.polyline({{0, 0}, {10, 10}}, {"none", "black", 1.0, 0.5, "4 2"});
  svg.polygon({{0, 0}, {10, 0}, {10, 10}}, {"grey", "none", 1.0, 1.0, {}});
  svg.polygon({{0, 0}, {10, 0}}, {"grey", "none", 1.0, 1.0, {}});  // too few points: nothing
  svg.text(5, 5, "A & <B>", {});
  const std::string text = svg.str();  // the open group is closed
  EXPECT_EQ(text.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg ", 0), 0u);
  EXPECT_EQ(count(text, "<g"), count(text, "</g>"));
  EXPECT_EQ(count(text, "<polygon"), 1);
  EXPECT_NE(text.find(">A &amp; &lt;B&gt;</text>"), std::string::npos);
  EXPECT_NE(text.find("stroke-dasharray=\"4 2\""), std::string::npos);
  const auto xml = xml_problems(svg, "basic.svg");
  EXPECT_EQ(xml.value_or(""), "");
  EXPECT_FALSE(svg.write("/proc/canyon-cannot-create/x.svg").ok());
  if (!xml) GTEST_SKIP() << kNoXmllint;
}

TEST(Plots, NiceTicks) {
  EXPECT_EQ(nice_ticks(0.0, 10.0, 6), (std::vector<double>{0, 2, 4, 6, 8, 10}));
  EXPECT_EQ(nice_ticks(-3.2, 7.9, 4), (std::vector<double>{0, 5}));
  const auto small = nice_ticks(0.0012, 0.0049, 5);  // step 0.00093 rounds up to 0.001
  ASSERT_EQ(small.size(), 3u);
  EXPECT_NEAR(small.front(), 0.002, 1e-12);
  EXPECT_NEAR(small.back(), 0.004, 1e-12);
  EXPECT_GE(nice_ticks(1.0, 1.3, 2).size(), 2u);
}

const char* const kCity = R"({"type":"FeatureCollection","features":[
{"type":"Feature","geometry":{"type":"Polygon","coordinates":[[[139.0001,35.0001],[139.0003,35.0001],[139.0003,35.0002],[139.0001,35.0002],[139.0001,35.0001]]]},"properties":{"kind":"building","height_m":42.5}},
{"type":"Feature","geometry":{"type":"Point","coordinates":[139.0,35.0]},"properties":{"kind":"tree","radius_m":2.5,"bottom_m":3,"top_m":9}},
{"type":"Feature","geometry":{"type":"LineString","coordinates":[[139.0,35.0],[139.001,35.0]]},"properties":{"kind":"route"}},
{"type":"Feature","geometry":{"type":"Point","coordinates":[139.1,35.1]},"properties":{"kind":"base","height_m":40.0}},
{"type":"Feature","geometry":{"type":"Point","coordinates":[139.0,35.0]},"properties":{"kind":"origin","height_m":40.0}}
]}
)";

TEST(CityMap, ReadsWhatSimulateWrites) {
  const auto city = read_city_geojson(write_file("city.geojson", kCity).string());
  ASSERT_TRUE(city.ok()) << city.error().to_string();
  ASSERT_EQ(city->buildings.size(), 1u);
  EXPECT_EQ(city->buildings[0].lon_lat_deg.size(), 4u);  // the closing point dropped
  EXPECT_DOUBLE_EQ(city->buildings[0].height_m, 42.5);
  ASSERT_EQ(city->trees.size(), 1u);
  EXPECT_DOUBLE_EQ(city->trees[0].radius_m, 2.5);
  EXPECT_EQ(city->route_lon_lat_deg.size(), 2u);
  ASSERT_TRUE(city->origin.has_value());
  EXPECT_NEAR(city->origin->lat_rad * core::kRadToDeg, 35.0, 1e-12);
  EXPECT_DOUBLE_EQ(city->origin->height_m, 40.0);
}

TEST(CityMap, BrokenFilesNameTheLineAndWhat) {
  struct Case {
    const char* text;
    int line;
    const char* message;
  };
  const Case cases[] = {
      {"{\"type\":\"FeatureCollection\",\"features\":[\n{\"type\":\"Feature\",\n\"geometry\":{\"type\":\"Point\" "
       "\"coordinates\":[1,2]}}]}",
       3, "JSON: expected ',' or '}' in an object"},
      {"{\"type\":\"FeatureCollection\",\"features\":[\n", 2, "unexpected end of file"},
      {"\n{\"type\":\"Feature\"}", 2, "not a GeoJSON FeatureCollection"},
      {"{\"type\":\"FeatureCollection\",\"features\":[\n{\"type\":\"Feature\",\"properties\":{}}]}", 2,
       "feature without a geometry object"},
      {"{\"type\":\"FeatureCollection\",\"features\":[\n{\"geometry\":{\"type\":\"Polygon\",\"coordinates\":\n"
       "[[[1,2],[3,4]]]},\"properties\":{\"kind\":\"building\"}}]}",
       3, "building polygon has fewer than three points"},
      {"{\"type\":\"FeatureCollection\",\"features\":[\n{\"geometry\":{\"type\":\"Point\",\"coordinates\":[1,95]},"
       "\"properties\":{\"kind\":\"tree\"}}]}",
       2, "longitude or latitude out of range"},
      {"{\"type\":\"FeatureCollection\",\"features\":[\n{\"geometry\":{\"type\":\"Point\",\"coordinates\":[1,x]},"
       "\"properties\":{\"kind\":\"tree\"}}]}",
       2, "unexpected character 'x'"},
  };
  int k = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.message);
    const fs::path path = write_file("broken" + std::to_string(k++) + ".geojson", c.text);
    const auto city = read_city_geojson(path.string());
    ASSERT_FALSE(city.ok());
    EXPECT_EQ(city.error().file, path.string());
    EXPECT_EQ(city.error().line, c.line) << city.error().to_string();
    EXPECT_NE(city.error().message.find(c.message), std::string::npos) << city.error().to_string();
  }
  EXPECT_FALSE(read_city_geojson("/nonexistent/city.geojson").ok());
}

/// Two solutions along a 20 m walk east of the city origin; B has one epoch 500 m off.
struct PlotCase {
  Truth truth = Truth::constant(Eigen::Vector3d::Zero());
  EvaluationReport report;
};

PlotCase plot_case() {
  const core::Geodetic origin{35.0 * core::kDegToRad, 139.0 * core::kDegToRad, 40.0};
  const core::GpsTime t0{2244, 36000.0};
  std::vector<TruthSample> samples;
  for (int k = 0; k <= 20; ++k) {
    samples.push_back({t0 + k, core::geodetic_to_ecef(origin) + core::enu_to_ecef({1.0 * k, 5.0, 1.7}, origin)});
  }
  PlotCase c{*Truth::from_samples(samples), {}};
  std::vector<SolutionInput> inputs(2);
  inputs[0].label = "RTKLIB & co";
  inputs[1].label = "canyon";
  for (int k = 0; k <= 20; ++k) {
    for (std::size_t i = 0; i < 2; ++i) {
      core::Solution s;
      s.time = samples[static_cast<std::size_t>(k)].time;
      s.status = k % 4 == 0 ? core::SolutionStatus::Float : core::SolutionStatus::Fixed;
      if (i == 1 && k == 7) s.status = core::SolutionStatus::VioFillIn;
      const double off_m = i == 1 && k == 10 ? 500.0 : 0.01 * (1 + k % 3);
      s.p_E_m = samples[static_cast<std::size_t>(k)].p_E_m + core::enu_to_ecef({off_m, 0.0, 0.0}, origin);
      inputs[i].solutions.push_back(s);
    }
  }
  c.report = *evaluate_report(std::move(inputs), c.truth, "truth.csv");
  return c;
}

TEST(Plots, TrajectoryPanelPerSolutionOverTheCity) {
  const PlotCase c = plot_case();
  const auto city = read_city_geojson(write_file("city.geojson", kCity).string());
  ASSERT_TRUE(city.ok());
  const SvgDocument svg = trajectory_plot(c.report, c.truth, &*city);
  const std::string text = svg.str();
  EXPECT_EQ(count(text, "<clipPath id=\"panel"), 2);
  EXPECT_NE(text.find(">RTKLIB &amp; co</text>"), std::string::npos);
  EXPECT_NE(text.find(">canyon</text>"), std::string::npos);
  EXPECT_NE(text.find(">fixed 71.4 %, 3D RMSE "), std::string::npos);  // 15 of 21 epochs
  EXPECT_NE(text.find(">fixed 66.7 %, 3D RMSE "), std::string::npos);  // 14: one fill-in
  EXPECT_NE(text.find("origin: city origin"), std::string::npos);
  EXPECT_NE(text.find("1 outside the frame"), std::string::npos);    // B's 500 m epoch
  EXPECT_EQ(count(text, "fill=\"#ffffff\" stroke=\"#222222\""), 2);  // one fill-in dot and its legend entry
  EXPECT_GE(count(text, "<polygon"), 2);                             // the building in both panels
  EXPECT_NE(text.find(">east (m)<"), std::string::npos);
  EXPECT_NE(text.find(">north (m)<"), std::string::npos);
  const auto xml = xml_problems(svg, "trajectory.svg");
  EXPECT_EQ(xml.value_or(""), "");
  // Equal scale: the plot area's size follows the frame (20 m east, at least 1/3 of that north).
  std::smatch m;
  const std::string clip = text.substr(text.find("<clipPath id=\"panel0\">"));
  ASSERT_TRUE(std::regex_search(clip, m, std::regex("width=\"([0-9.]+)\" height=\"([0-9.]+)\"")));
  EXPECT_NEAR(std::stod(m[1].str()) / std::stod(m[2].str()), 3.0, 0.01);

  const SvgDocument no_city = trajectory_plot(c.report, c.truth, nullptr);
  EXPECT_NE(no_city.str().find("origin: first truth point"), std::string::npos);
  EXPECT_EQ(count(no_city.str(), "<polygon"), 0);
  if (!xml) GTEST_SKIP() << kNoXmllint;
}

TEST(Plots, ApeOverTimeWithThresholdAndLegend) {
  const PlotCase c = plot_case();
  const SvgDocument svg = ape_plot(c.report, c.truth);
  const std::string text = svg.str();
  EXPECT_NE(text.find("wrong-fix threshold 10 cm"), std::string::npos);
  EXPECT_NE(text.find(">RTKLIB &amp; co</text>"), std::string::npos);
  EXPECT_NE(text.find(">canyon</text>"), std::string::npos);
  // Decades from 1 cm (smallest error) to 1 km (500 m).
  for (const char* label : {">1 cm<", ">10 cm<", ">1 m<", ">10 m<", ">100 m<", ">1 km<"}) {
    EXPECT_NE(text.find(label), std::string::npos) << label;
  }
  EXPECT_EQ(text.find(">1 mm<"), std::string::npos);
  EXPECT_NE(text.find("time since 2023-01-08 10:00:00 GPST (s)"), std::string::npos);
  const auto xml = xml_problems(svg, "ape.svg");
  EXPECT_EQ(xml.value_or(""), "");
  if (!xml) GTEST_SKIP() << kNoXmllint;
}

}  // namespace
}  // namespace canyon::eval
