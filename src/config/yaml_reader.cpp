// Strict YAML reading (see yaml_reader.hpp).

#include "canyon/config/yaml_reader.hpp"

#include <set>
#include <utility>

namespace canyon::config {

YamlMap::YamlMap(const YAML::Node& node, std::string file, std::string path)
    : node_(node), file_(std::move(file)), path_(std::move(path)), errors_(std::make_shared<std::vector<Error>>()) {
  if (node_ && !node_.IsNull() && !node_.IsMap()) {
    errors_->push_back(Error{(path_.empty() ? std::string("top level") : "'" + path_ + "'") + " must be a map of keys",
                             file_, node_.Mark().line + 1});
    node_ = YAML::Node();
  }
}

std::string YamlMap::key_path(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

int YamlMap::line_of(const std::string& key) const {
  if (!node_ || !node_.IsMap()) return 0;
  for (const auto& item : node_) {
    if (item.first.Scalar() == key) return item.first.Mark().line + 1;
  }
  return node_.Mark().line + 1;
}

bool YamlMap::has(const std::string& key) const {
  return node_ && node_.IsMap() && node_[key].IsDefined();
}

template <typename T>
void YamlMap::get_scalar(const std::string& key, T& out, const char* type_name) {
  asked_.insert(key);
  if (!has(key)) return;
  const YAML::Node value = node_[key];
  try {
    if (!value.IsScalar()) throw YAML::Exception(value.Mark(), "not a scalar");
    out = value.as<T>();
  } catch (const YAML::Exception&) {
    fail(key, std::string("must be ") + type_name);
  }
}

void YamlMap::get(const std::string& key, double& out) {
  get_scalar(key, out, "a number");
}
void YamlMap::get(const std::string& key, int& out) {
  get_scalar(key, out, "an integer");
}
void YamlMap::get(const std::string& key, bool& out) {
  get_scalar(key, out, "true or false");
}
void YamlMap::get(const std::string& key, std::string& out) {
  get_scalar(key, out, "a string");
}

void YamlMap::get(const std::string& key, std::vector<std::string>& out) {
  asked_.insert(key);
  if (!has(key)) return;
  const YAML::Node value = node_[key];
  if (value.IsScalar()) {  // a single item may be written without brackets
    out = {value.as<std::string>()};
    return;
  }
  if (!value.IsSequence()) {
    fail(key, "must be a list");
    return;
  }
  std::vector<std::string> items;
  for (const auto& item : value) {
    if (!item.IsScalar()) {
      fail(key, "must be a list of strings");
      return;
    }
    items.push_back(item.as<std::string>());
  }
  out = std::move(items);
}

namespace {

/// The numbers of a sequence node; false if it is not a sequence of numbers.
bool read_numbers(const YAML::Node& node, std::vector<double>& out) {
  if (!node.IsSequence()) return false;
  std::vector<double> values;
  for (const auto& item : node) {
    if (!item.IsScalar()) return false;
    try {
      values.push_back(item.as<double>());
    } catch (const YAML::Exception&) {
      return false;
    }
  }
  out = std::move(values);
  return true;
}

}  // namespace

void YamlMap::get(const std::string& key, std::vector<double>& out) {
  asked_.insert(key);
  if (!has(key)) return;
  if (!read_numbers(node_[key], out)) fail(key, "must be a list of numbers");
}

void YamlMap::get(const std::string& key, std::vector<std::vector<double>>& out) {
  asked_.insert(key);
  if (!has(key)) return;
  const YAML::Node value = node_[key];
  if (!value.IsSequence()) {
    fail(key, "must be a list of lists of numbers");
    return;
  }
  std::vector<std::vector<double>> rows;
  for (const auto& item : value) {
    std::vector<double> row;
    if (!read_numbers(item, row)) {
      fail(key, "must be a list of lists of numbers");
      return;
    }
    rows.push_back(std::move(row));
  }
  out = std::move(rows);
}

YamlMap YamlMap::sub(const std::string& key) {
  asked_.insert(key);
  YamlMap child(has(key) ? node_[key] : YAML::Node(), file_, key_path(key));
  // Errors from the child's constructor go into our sink too.
  errors_->insert(errors_->end(), child.errors_->begin(), child.errors_->end());
  child.errors_ = errors_;
  return child;
}

YAML::Node YamlMap::raw(const std::string& key) {
  asked_.insert(key);
  return has(key) ? node_[key] : YAML::Node();
}

void YamlMap::add_error(Error error) {
  errors_->push_back(std::move(error));
}

void YamlMap::fail(const std::string& key, const std::string& message) {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "'" + std::string.
  std::string text = "'";
  text.append(key_path(key)).append("' ").append(message);
  errors_->push_back(Error{std::move(text), file_, line_of(key)});
}

void YamlMap::reject_unknown_keys() {
  if (!node_ || !node_.IsMap()) return;
  std::set<std::string> seen;
  for (const auto& item : node_) {
    const std::string key = item.first.Scalar();
    const int line = item.first.Mark().line + 1;
    if (asked_.count(key) == 0) {
      errors_->push_back(Error{"unknown key '" + key_path(key) + "'", file_, line});
    } else if (!seen.insert(key).second) {
      // YAML maps have unique keys; yaml-cpp keeps both and reads the first, so the second would be ignored silently.
      errors_->push_back(Error{"duplicate key '" + key_path(key) + "' (given earlier in the same map)", file_, line});
    }
  }
}

Status YamlMap::status() const {
  if (errors_->empty()) return Ok{};
  return errors_->front();
}

Result<YAML::Node> load_yaml_file(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    return Error{"cannot open configuration file", path, 0};
  } catch (const YAML::ParserException& e) {
    return Error{"YAML syntax error: " + e.msg, path, e.mark.line + 1};
  } catch (const YAML::Exception& e) {
    return Error{std::string("YAML error: ") + e.what(), path, 0};
  }
}

}  // namespace canyon::config
