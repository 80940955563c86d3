// Options described once: printing, descriptions and the codecs shared by the tables (see options_table.hpp).

#include "canyon/config/options_table.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace canyon::config {

std::string resolve_path(const std::string& path, const std::string& file) {
  if (path.empty() || file.empty() || std::filesystem::path(path).is_absolute()) return path;
  return (std::filesystem::path(file).parent_path() / path).lexically_normal().string();
}

std::string shortest_number(double value) {
  char buffer[40];
  int precision = 1;
  for (; precision <= 17; ++precision) {
    std::snprintf(buffer, sizeof buffer, "%.*g", precision, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  // %g writes 600 as 6e+02 at one digit: more digits, until the integer part is written out (up to 17). A correctly
  // rounded decimal with more digits is at least as close to the value, so it still reads back the same.
  while (std::strstr(buffer, "e+") != nullptr && precision < 17) {
    std::snprintf(buffer, sizeof buffer, "%.*g", ++precision, value);
  }
  return buffer;
}

std::string format_descriptions(const std::vector<KeyDescription>& keys) {
  std::size_t key_width = 3, unit_width = 4, default_width = 7;
  const auto shown_default = [](const KeyDescription& k) {
    return k.default_value.empty() ? "(unset)" : k.default_value;
  };
  for (const KeyDescription& k : keys) {
    key_width = std::max(key_width, k.path.size());
    unit_width = std::max(unit_width, k.unit.size());
    default_width = std::max(default_width, shown_default(k).size());
  }
  const auto row = [&](const std::string& key, const std::string& unit, const std::string& value,
                       const std::string& doc) {
    std::string line = key;
    line.append(key_width + 2 - key.size(), ' ').append(unit);
    line.append(unit_width + 2 - unit.size(), ' ').append(value);
    line.append(default_width + 2 - value.size(), ' ').append(doc);
    return line + "\n";
  };
  std::string text = row("key", "unit", "default", "meaning");
  for (const KeyDescription& k : keys) text += row(k.path, k.unit.empty() ? "-" : k.unit, shown_default(k), k.doc);
  return text;
}

void Reading::fail(const std::string& message) {
  map_.fail(key_, message);
  failed_ = true;
}

Printer::Printer(YAML::Emitter& out, Numbers numbers) : out_(out), numbers_(numbers) {
  if (numbers_ == Numbers::Digits12) out_.SetDoublePrecision(12);
}

void Printer::key(const std::string& key) {
  out_ << YAML::Key << key << YAML::Value;
}

void Printer::begin_map() {
  out_ << YAML::BeginMap;
}

void Printer::end_map() {
  out_ << YAML::EndMap;
}

void Printer::number(double v) {
  if (numbers_ == Numbers::Shortest) {
    out_ << shortest_number(v);
  } else {
    out_ << v;
  }
}

void Printer::value(double v) {
  number(v);
}

void Printer::value(int v) {
  out_ << v;
}

void Printer::value(bool v) {
  out_ << v;
}

void Printer::value(const std::string& v, bool quoted) {
  if (quoted) out_ << YAML::DoubleQuoted;
  out_ << v;
}

void Printer::value(const std::vector<std::string>& v) {
  out_ << YAML::Flow << YAML::BeginSeq;
  for (const std::string& item : v) out_ << item;
  out_ << YAML::EndSeq;
}

void Printer::value(const std::vector<double>& v) {
  out_ << YAML::Flow << YAML::BeginSeq;
  for (const double x : v) number(x);
  out_ << YAML::EndSeq;
}

void Printer::value(const std::vector<std::vector<double>>& v) {
  out_ << YAML::Flow << YAML::BeginSeq;
  for (const std::vector<double>& row : v) value(row);
  out_ << YAML::EndSeq;
}

std::string must_be_one_of(const std::vector<std::string>& names, const std::string& value) {
  std::string list;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) list += i + 1 == names.size() ? " or " : ", ";
    list += names[i];
  }
  return "must be " + list + ", not '" + value + "'";
}

void Paths::from(const Yaml& value, Yaml& paths, Reading& reading) const {
  paths = value;
  for (std::string& p : paths) p = resolve_path(p, reading.file());
}

Satellites::Yaml Satellites::to(const std::vector<core::SatelliteId>& sats) const {
  Yaml texts;
  texts.reserve(sats.size());
  for (const core::SatelliteId& sat : sats) texts.push_back(sat.to_string());
  return texts;
}

void Satellites::from(const Yaml& value, std::vector<core::SatelliteId>& sats, Reading& reading) const {
  sats.clear();
  for (const std::string& text : value) {
    const auto sat = core::parse_satellite(text);
    if (!sat) {
      reading.fail("has '" + text + "', not a satellite (e.g. G05, R12, E30, C20, J02)");
    } else {
      sats.push_back(*sat);
    }
  }
}

void Systems::from(const Yaml& value, core::ConstellationFlags& flags, Reading& reading) const {
  std::string bad;
  if (!flags.set_from_letters(value, &bad)) reading.fail("has '" + bad + "'; allowed: " + allowed);
}

void Vector3::from(const Yaml& value, Eigen::Vector3d& v, Reading& reading) const {
  if (value.size() != 3) {
    reading.fail(rule);
    return;
  }
  v = Eigen::Vector3d(value[0], value[1], value[2]);
}

}  // namespace canyon::config
