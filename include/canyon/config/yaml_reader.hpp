#pragma once
// Strict YAML reading for configuration structs: every key must be known, every value of the right type; the error
// names the file, the line and the key path ("spp.elevation_mask_deg"). A misspelt key is an error, never a
// silent default.

#include <memory>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "canyon/core/result.hpp"

namespace canyon::config {

class YamlMap {
 public:
  /// `node` must be a map (or null, read as empty); `path` is the key path of the node ("" at the top).
  YamlMap(const YAML::Node& node, std::string file, std::string path = {});

  /// Reads `key` into `out` if present (leaves `out` unchanged if absent). Records an error on a type mismatch.
  void get(const std::string& key, double& out);
  void get(const std::string& key, int& out);
  void get(const std::string& key, bool& out);
  void get(const std::string& key, std::string& out);
  void get(const std::string& key, std::vector<std::string>& out);
  /// A list of numbers ([1, 2.5, 3]).
  void get(const std::string& key, std::vector<double>& out);
  /// A list of lists of numbers ([[0, 0], [100, 0]]).
  void get(const std::string& key, std::vector<std::vector<double>>& out);
  /// The sub-map at `key` (empty if absent).
  [[nodiscard]] YamlMap sub(const std::string& key);
  /// The node at `key` as it is (undefined if absent), for a reader of its own; `key` counts as known.
  [[nodiscard]] YAML::Node raw(const std::string& key);
  [[nodiscard]] bool has(const std::string& key) const;
  /// The file this map was read from (errors name it; relative paths are relative to its folder).
  [[nodiscard]] const std::string& file() const { return file_; }

  /// Records an error for every key of this map that was never asked for (call once all keys were read).
  void reject_unknown_keys();
  /// The first error recorded in this map or any map obtained from it with sub().
  [[nodiscard]] Status status() const;
  /// Records an error about the value of `key` (e.g. an enumeration value that is not allowed).
  void fail(const std::string& key, const std::string& message);
  /// Records an error found by a reader of its own (raw()).
  void add_error(Error error);

 private:
  [[nodiscard]] std::string key_path(const std::string& key) const;
  [[nodiscard]] int line_of(const std::string& key) const;
  template <typename T>
  void get_scalar(const std::string& key, T& out, const char* type_name);

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> asked_;
  std::shared_ptr<std::vector<Error>> errors_;  // shared with sub-maps
};

/// Loads a YAML file; Error with file and line on a syntax error.
Result<YAML::Node> load_yaml_file(const std::string& path);

}  // namespace canyon::config
