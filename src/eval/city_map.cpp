// Reading city.geojson for plots (see city_map.hpp): a small JSON parser that keeps line numbers, then the
// features canyon simulate writes.

#include "canyon/eval/city_map.hpp"

#include <charconv>
#include <cmath>
#include <string_view>
#include <tuple>
#include <utility>

#include "canyon/core/constants.hpp"
#include "canyon/io/text_reader.hpp"

namespace canyon::eval {
namespace {

struct JsonValue {
  enum class Kind { Null, Bool, Number, String, Array, Object };
  Kind kind = Kind::Null;
  bool boolean = false;
  double number = 0.0;
  std::string text;
  std::vector<JsonValue> items;           ///< array elements
  std::vector<std::string> member_names;  ///< object members, in file order ...
  std::vector<JsonValue> member_values;   ///< ... and their values
  int line = 0;                           ///< where the value starts

  [[nodiscard]] const JsonValue* find(std::string_view key) const {
    for (std::size_t k = 0; k < member_names.size(); ++k) {
      if (member_names[k] == key) return &member_values[k];
    }
    return nullptr;
  }
  [[nodiscard]] bool is(Kind k) const { return kind == k; }
};

/// Recursive-descent JSON (RFC 8259) parser; errors carry the line.
class JsonParser {
 public:
  JsonParser(std::string_view text, std::string path) : text_(text), path_(std::move(path)) {}

  Result<JsonValue> parse_document() {
    auto value = parse_value(0);
    if (!value) return value;
    skip_blanks();
    if (pos_ != text_.size()) return error("unexpected text after the JSON value");
    return value;
  }

 private:
  static constexpr int kMaxDepth = 64;

  Error error(const std::string& message) const { return Error{"JSON: " + message, path_, line_}; }

  void skip_blanks() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
      } else if (c != ' ' && c != '\t' && c != '\r') {
        return;
      }
      ++pos_;
    }
  }

  bool consume(char c) {
    skip_blanks();
    if (pos_ < text_.size() && text_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }

  Result<JsonValue> parse_value(int depth) {
    if (depth > kMaxDepth) return error("nested too deeply");
    skip_blanks();
    if (pos_ >= text_.size()) return error("unexpected end of file, expected a value");
    JsonValue v;
    v.line = line_;
    const char c = text_[pos_];
    if (c == '{') return parse_object(std::move(v), depth);
    if (c == '[') return parse_array(std::move(v), depth);
    if (c == '"') {
      auto s = parse_string();
      if (!s) return s.error();
      v.kind = JsonValue::Kind::String;
      v.text = std::move(*s);
      return v;
    }
    for (const auto& [word, kind, flag] :
         {std::tuple{"true", JsonValue::Kind::Bool, true}, std::tuple{"false", JsonValue::Kind::Bool, false},
          std::tuple{"null", JsonValue::Kind::Null, false}}) {
      const std::string_view w = word;
      if (text_.substr(pos_, w.size()) == w) {
        pos_ += w.size();
        v.kind = kind;
        v.boolean = flag;
        return v;
      }
    }
    return parse_number(std::move(v));
  }

  Result<JsonValue> parse_number(JsonValue v) {
    const std::size_t start = pos_;
    while (pos_ < text_.size() && std::string_view("+-0123456789.eE").find(text_[pos_]) != std::string_view::npos) {
      ++pos_;
    }
    const std::string_view token = text_.substr(start, pos_ - start);
    if (token.empty()) return error(std::string("unexpected character '") + text_[start] + "'");
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v.number);
    if (ec != std::errc{} || end != token.data() + token.size()) {
      return error("bad number '" + std::string(token) + "'");
    }
    v.kind = JsonValue::Kind::Number;
    return v;
  }

  Result<std::string> parse_string() {
    ++pos_;  // opening quote
    std::string out;
    while (pos_ < text_.size()) {
      const char c = text_[pos_++];
      if (c == '"') return out;
      if (c == '\n') return error("line break inside a string");
      if (c != '\\') {
        out += c;
        continue;
      }
      if (pos_ >= text_.size()) break;
      const char e = text_[pos_++];
      switch (e) {
        case 'n': out += '\n'; break;
        case 't': out += '\t'; break;
        case 'r': out += '\r'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'u':
          // Names and kinds are ASCII; other code points are kept as '?'.
          if (pos_ + 4 > text_.size()) return error("bad \\u escape");
          pos_ += 4;
          out += '?';
          break;
        default: out += e;
      }
    }
    return error("unterminated string");
  }

  Result<JsonValue> parse_array(JsonValue v, int depth) {
    ++pos_;
    v.kind = JsonValue::Kind::Array;
    if (consume(']')) return v;
    while (true) {
      auto item = parse_value(depth + 1);
      if (!item) return item;
      v.items.push_back(std::move(*item));
      if (consume(']')) return v;
      if (!consume(',')) return error("expected ',' or ']' in an array");
    }
  }

  Result<JsonValue> parse_object(JsonValue v, int depth) {
    ++pos_;
    v.kind = JsonValue::Kind::Object;
    if (consume('}')) return v;
    while (true) {
      skip_blanks();
      if (pos_ >= text_.size() || text_[pos_] != '"') return error("expected a member name in quotes");
      auto name = parse_string();
      if (!name) return name.error();
      if (!consume(':')) return error("expected ':' after member name '" + *name + "'");
      auto value = parse_value(depth + 1);
      if (!value) return value;
      v.member_names.push_back(std::move(*name));
      v.member_values.push_back(std::move(*value));
      if (consume('}')) return v;
      if (!consume(',')) return error("expected ',' or '}' in an object");
    }
  }

  std::string_view text_;
  std::string path_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

Result<std::string> read_whole_file(const std::string& path) {
  auto reader = io::TextReader::open(path);
  if (!reader) return reader.error();
  std::string text;
  while (auto line = reader->next_line()) {
    text.append(*line);
    text += '\n';
  }
  if (reader->read_error()) return reader->error(*reader->read_error());
  return text;
}

/// [lon, lat] in range.
Result<Eigen::Vector2d> lon_lat(const JsonValue& v, const std::string& path) {
  if (!v.is(JsonValue::Kind::Array) || v.items.size() < 2 || !v.items[0].is(JsonValue::Kind::Number) ||
      !v.items[1].is(JsonValue::Kind::Number)) {
    return Error{"a position is not [longitude, latitude]", path, v.line};
  }
  const double lon_deg = v.items[0].number;
  const double lat_deg = v.items[1].number;
  if (std::abs(lon_deg) > 360.0 || std::abs(lat_deg) > 90.0) {
    return Error{"longitude or latitude out of range", path, v.line};
  }
  return Eigen::Vector2d(lon_deg, lat_deg);
}

Result<std::vector<Eigen::Vector2d>> lon_lat_list(const JsonValue& v, const std::string& path) {
  if (!v.is(JsonValue::Kind::Array)) return Error{"coordinates are not a list of positions", path, v.line};
  std::vector<Eigen::Vector2d> out;
  out.reserve(v.items.size());
  for (const JsonValue& item : v.items) {
    auto p = lon_lat(item, path);
    if (!p) return p.error();
    out.push_back(*p);
  }
  return out;
}

double number_property(const JsonValue* properties, std::string_view key, double fallback) {
  const JsonValue* v = properties != nullptr ? properties->find(key) : nullptr;
  return v != nullptr && v->is(JsonValue::Kind::Number) ? v->number : fallback;
}

Status add_polygon(const JsonValue& coordinates, const JsonValue* properties, const std::string& path, CityMap& map) {
  if (!coordinates.is(JsonValue::Kind::Array) || coordinates.items.empty()) {
    return Error{"polygon coordinates are not a list of rings", path, coordinates.line};
  }
  auto ring = lon_lat_list(coordinates.items.front(), path);
  if (!ring) return ring.error();
  if (ring->size() > 1 && ring->front() == ring->back()) ring->pop_back();
  if (ring->size() < 3) return Error{"building polygon has fewer than three points", path, coordinates.line};
  const double height_m = number_property(properties, "height_m", 0.0);
  if (!(height_m >= 0.0)) return Error{"building height_m is negative", path, coordinates.line};
  map.buildings.push_back({std::move(*ring), height_m});
  return Ok{};
}

Status add_feature(const JsonValue& feature, const std::string& path, CityMap& map) {
  if (!feature.is(JsonValue::Kind::Object)) return Error{"a feature is not an object", path, feature.line};
  const JsonValue* geometry = feature.find("geometry");
  if (geometry == nullptr || !geometry->is(JsonValue::Kind::Object)) {
    return Error{"feature without a geometry object", path, feature.line};
  }
  const JsonValue* type = geometry->find("type");
  const JsonValue* coordinates = geometry->find("coordinates");
  if (type == nullptr || !type->is(JsonValue::Kind::String) || coordinates == nullptr) {
    return Error{"geometry without type or coordinates", path, geometry->line};
  }
  const JsonValue* properties = feature.find("properties");
  const JsonValue* kind_value = properties != nullptr ? properties->find("kind") : nullptr;
  const std::string kind = kind_value != nullptr && kind_value->is(JsonValue::Kind::String) ? kind_value->text : "";
  if (type->text == "Polygon" && (kind.empty() || kind == "building")) {
    return add_polygon(*coordinates, properties, path, map);
  }
  if (type->text == "Point" && (kind == "tree" || kind == "origin")) {
    auto p = lon_lat(*coordinates, path);
    if (!p) return p.error();
    if (kind == "tree") {
      map.trees.push_back({*p, number_property(properties, "radius_m", 3.0)});
    } else {
      map.origin = core::Geodetic{p->y() * core::kDegToRad, p->x() * core::kDegToRad,
                                  number_property(properties, "height_m", 0.0)};
    }
    return Ok{};
  }
  if (type->text == "LineString" && kind == "route") {
    auto points = lon_lat_list(*coordinates, path);
    if (!points) return points.error();
    map.route_lon_lat_deg = std::move(*points);
  }
  return Ok{};
}

}  // namespace

Result<CityMap> read_city_geojson(const std::string& path) {
  auto text = read_whole_file(path);
  if (!text) return text.error();
  auto root = JsonParser(*text, path).parse_document();
  if (!root) return root.error();
  const JsonValue* type = root->find("type");
  const JsonValue* features = root->find("features");
  if (!root->is(JsonValue::Kind::Object) || type == nullptr || !type->is(JsonValue::Kind::String) ||
      type->text != "FeatureCollection" || features == nullptr || !features->is(JsonValue::Kind::Array)) {
    return Error{"not a GeoJSON FeatureCollection with a features list", path, root->line};
  }
  CityMap map;
  for (const JsonValue& feature : features->items) {
    if (Status s = add_feature(feature, path, map); !s) return s.error();
  }
  return map;
}

}  // namespace canyon::eval
