// The shipped files in config/ cannot drift from the code: every key of every table appears in its shipped file
// (config/spp.yaml, rtk.yaml, fusion.yaml, rover.yaml, base.yaml, scenarios/*.yaml; a commented-out example counts)
// and, where the table gives a unit, the file's comment on the key gives the same unit in parentheses: "(deg)",
// "(m, 1 sigma)", "(m; ...)". The checker itself must catch a missing key and a wrong unit (last test).

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "canyon/config/base_config.hpp"
#include "canyon/config/process_config.hpp"
#include "canyon/config/rover_config.hpp"
#include "canyon/config/scenario_config.hpp"

namespace canyon::config {
namespace {

namespace fs = std::filesystem;
const fs::path kConfig = fs::path(CANYON_SOURCE_DIR) / "config";

/// The keys a shipped file shows (commented-out examples "# key: value" included), each with its doc: its inline
/// comment with the comment lines that continue it (indented beyond the key), or, without an inline comment, the
/// comment lines right above it at its indentation.
struct ShippedFile {
  std::string name;                         ///< for messages ("config/rtk.yaml")
  std::map<std::string, std::string> docs;  ///< by dotted key path
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

ShippedFile shown_keys(const std::string& name, const std::string& text) {
  static const std::regex key_line(R"(^( *)([A-Za-z0-9_]+):(?: (.*))?$)");
  static const std::regex commented_key(R"(^( *)# ([a-z0-9_]+):(?: (.*))?$)");
  static const std::regex comment_only(R"(^( *)#(.*)$)");
  ShippedFile file{name, {}};
  std::vector<std::pair<std::size_t, std::string>> parents;  // (indentation, key)
  std::string last_path;
  std::size_t last_indent = 0;
  bool continuing = false;                                 // comment lines may still continue the last key's doc
  std::vector<std::pair<std::size_t, std::string>> above;  // comment-only lines since the last key: (indentation, text)
  std::istringstream in(text);
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, comment_only) && continuing && m[1].length() > static_cast<long>(last_indent)) {
      file.docs[last_path] += " " + m[2].str();
      continue;
    }
    const bool is_key = std::regex_match(line, m, key_line) || std::regex_match(line, m, commented_key);
    if (!is_key) {
      continuing = false;
      if (std::regex_match(line, m, comment_only)) {
        above.emplace_back(m[1].length(), m[2].str());
      } else {
        above.clear();
      }
      continue;
    }
    const std::size_t indent = m[1].length();
    while (!parents.empty() && parents.back().first >= indent) parents.pop_back();
    std::string path;
    for (const auto& parent : parents) path += parent.second + ".";
    path += m[2].str();
    parents.emplace_back(indent, m[2].str());
    const std::string rest = m[3].str();
    const std::size_t hash = rest.find(" #");
    std::string doc;
    if (hash != std::string::npos) {
      doc = rest.substr(hash + 2);
    } else {
      for (const auto& [at_indent, comment] : above) {
        if (at_indent == static_cast<std::size_t>(m[1].length())) doc += " " + comment;
      }
    }
    file.docs[path] += doc;
    above.clear();
    last_path = path;
    last_indent = indent;
    continuing = hash != std::string::npos;
  }
  return file;
}

ShippedFile shipped(const std::string& relative) {
  return shown_keys("config/" + relative, read_text(kConfig / relative));
}

/// Whether a doc gives `unit` in parentheses, alone or as the first word of an item: "(deg)", "(m, 1 sigma)",
/// "(m; ...)", "(m from the origin)" (not "(m per sqrt(s))", another unit).
bool gives_unit(const std::string& doc, const std::string& unit) {
  for (std::size_t open = doc.find('('); open != std::string::npos; open = doc.find('(', open + 1)) {
    int depth = 0;
    std::size_t close = open;
    for (; close < doc.size(); ++close) {
      if (doc[close] == '(') ++depth;
      if (doc[close] == ')' && --depth == 0) break;
    }
    const std::string inside = doc.substr(open + 1, close - open - 1);
    std::size_t start = 0;
    while (start <= inside.size()) {
      std::size_t end = inside.find_first_of(",;", start);
      if (end == std::string::npos) end = inside.size();
      std::string item = inside.substr(start, end - start);
      item.erase(0, item.find_first_not_of(' '));
      item.erase(item.find_last_not_of(' ') + 1);
      if (item == unit || (item.rfind(unit + " ", 0) == 0 && item.rfind(unit + " per ", 0) != 0)) return true;
      start = end + 1;
    }
  }
  return false;
}

/// Whether the doc of the key's parent names it ("key:"), as rover.yaml's pipeline.cpu_affinity names its stages.
bool named_by_parent(const std::string& path, const ShippedFile& file) {
  const std::size_t dot = path.rfind('.');
  if (dot == std::string::npos) return false;
  const auto parent = file.docs.find(path.substr(0, dot));
  return parent != file.docs.end() && parent->second.find(path.substr(dot + 1) + ":") != std::string::npos;
}

/// What does not match: each key of `keys` must be shown by one of `files` (or named by its parent's doc there), and
/// its unit, if it has one, given where it is shown.
std::vector<std::string> drift(const std::vector<KeyDescription>& keys, const std::vector<ShippedFile>& files) {
  std::vector<std::string> problems;
  for (const KeyDescription& k : keys) {
    std::vector<std::pair<const ShippedFile*, const std::string*>> found;  // (file, doc)
    bool named = false;
    for (const ShippedFile& f : files) {
      if (auto it = f.docs.find(k.path); it != f.docs.end()) found.emplace_back(&f, &it->second);
      named = named || named_by_parent(k.path, f);
    }
    if (found.empty()) {
      if (named) continue;
      std::string names;
      for (const ShippedFile& f : files) names += (names.empty() ? "" : ", ") + f.name;
      problems.push_back(k.path + ": in none of " + names);
      continue;
    }
    if (k.unit.empty()) continue;
    bool unit_given = false;
    for (const auto& [file, doc] : found) unit_given = unit_given || gives_unit(*doc, k.unit);
    if (!unit_given) {
      problems.push_back(k.path + ": " + found.front().first->name + " does not give its unit (" + k.unit + ")");
    }
  }
  return problems;
}

/// The keys under `section.` (without the prefix), or those not under any of `sections`.
std::vector<KeyDescription> keys_under(const std::vector<KeyDescription>& keys, const std::string& section) {
  std::vector<KeyDescription> out;
  for (const KeyDescription& k : keys) {
    if (k.path.rfind(section + ".", 0) == 0) out.push_back(k);
  }
  return out;
}

std::vector<KeyDescription> keys_outside(const std::vector<KeyDescription>& keys,
                                         const std::vector<std::string>& sections) {
  std::vector<KeyDescription> out;
  for (const KeyDescription& k : keys) {
    bool inside = false;
    for (const std::string& s : sections) inside = inside || k.path.rfind(s + ".", 0) == 0;
    if (!inside) out.push_back(k);
  }
  return out;
}

std::string joined(const std::vector<std::string>& problems) {
  std::string text;
  for (const std::string& p : problems) text += "\n  " + p;
  return text;
}

TEST(ShippedKeys, EstimatorSectionsInSppRtkAndFusionYaml) {
  const auto keys = describe_process_config();
  EXPECT_EQ(joined(drift(keys_under(keys, "spp"), {shipped("spp.yaml")})), "");
  EXPECT_EQ(joined(drift(keys_under(keys, "rtk"), {shipped("rtk.yaml")})), "");
  EXPECT_EQ(joined(drift(keys_under(keys, "fusion"), {shipped("fusion.yaml")})), "");
}

TEST(ShippedKeys, ProcessKeysInTheProcessFilesOrTheRoversEstimator) {
  // The inputs (rover, base, nav, out, ...) are shown by the files that name them: rover.yaml's estimator section,
  // fusion.yaml (vio, timesync), rtk.yaml (base_position). `nmea` is shown by no shipped file yet: its doc is in
  // process_config.hpp and docs/usage.md (--nmea).
  std::vector<KeyDescription> keys;
  for (const KeyDescription& k : keys_outside(describe_process_config(), {"spp", "rtk", "fusion"})) {
    if (k.path != "nmea") keys.push_back(k);
  }
  ShippedFile rover = shipped("rover.yaml");
  ShippedFile estimator{"config/rover.yaml (estimator)", {}};
  for (const auto& [path, doc] : rover.docs) {
    if (path.rfind("estimator.", 0) == 0) estimator.docs[path.substr(10)] = doc;
  }
  EXPECT_EQ(joined(drift(keys, {shipped("spp.yaml"), shipped("rtk.yaml"), shipped("fusion.yaml"), estimator})), "");
}

TEST(ShippedKeys, RoverKeysInRoverYaml) {
  const auto keys = keys_outside(describe_rover_config(), {"estimator"});
  EXPECT_EQ(joined(drift(keys, {shipped("rover.yaml")})), "");
}

TEST(ShippedKeys, BaseKeysInBaseYaml) {
  EXPECT_EQ(joined(drift(describe_base_config(), {shipped("base.yaml")})), "");
}

TEST(ShippedKeys, ScenarioKeysInEveryShippedScenario) {
  int files = 0;
  for (const auto& entry : fs::directory_iterator(kConfig / "scenarios")) {
    if (entry.path().extension() != ".yaml") continue;
    ++files;
    EXPECT_EQ(joined(drift(describe_scenario(), {shipped("scenarios/" + entry.path().filename().string())})), "")
        << entry.path();
  }
  EXPECT_GE(files, 4);
}

TEST(ShippedKeys, TheCheckCatchesAMissingKeyAndAWrongUnit) {
  const auto rtk = keys_under(describe_process_config(), "rtk");
  std::string text = read_text(kConfig / "rtk.yaml");
  const std::size_t ratio = text.find("  ratio_threshold:");
  ASSERT_NE(ratio, std::string::npos);
  text.erase(ratio, text.find('\n', ratio) + 1 - ratio);
  const std::size_t mask = text.find("satellites below are not used (deg)");
  ASSERT_NE(mask, std::string::npos);
  text.replace(mask, 35, "satellites below are not used (rad)");
  EXPECT_EQ(joined(drift(rtk, {shown_keys("doctored rtk.yaml", text)})),
            joined({"rtk.elevation_mask_deg: doctored rtk.yaml does not give its unit (deg)",
                    "rtk.ratio_threshold: in none of doctored rtk.yaml"}));
  // Units in parentheses, alone or first in a list; another unit does not count.
  EXPECT_TRUE(gives_unit("a (b) c (m, 1 sigma)", "m"));
  EXPECT_TRUE(gives_unit("spread it needs (m; the yaw sigma bound decides: sigma = RMSE / spread)", "m"));
  EXPECT_TRUE(gives_unit("drift (deg per sqrt(km))", "deg per sqrt(km)"));
  EXPECT_FALSE(gives_unit("random walk (m per sqrt(s))", "m"));
  EXPECT_FALSE(gives_unit("in metres", "m"));
}

}  // namespace
}  // namespace canyon::config
