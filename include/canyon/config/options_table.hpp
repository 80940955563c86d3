#pragma once
// Options described once. The table of an options struct lists its YAML keys in the order of the shipped files, each
// with its unit as those files write it ("m", "deg", "s", "dB-Hz", ...; empty: none), a one-line doc, and how to reach
// the member: at(&S::a) or, through nested structs, at(&S::a, &A::b, &B::c), with a codec where the YAML form
// differs from the member's (degrees for radians, names for enumerations, satellites as text, ...). The default of
// a key is its member in a default-constructed struct: the in-class initialisers stay the one source of defaults.
// From the table alone:
//   read_keys()      parses a YAML map into the struct: strict, an unknown key is an error naming the file, the line
//                    and the key path; each key starts from the member's current value (an absent key keeps it)
//   yaml_text()      prints the struct as YAML, keys in table order
//   equal_keys()     compares two structs key by key: the member itself where it can be compared, else its YAML form
//   describe_keys()  every key's path, unit, default and doc (canyon process --describe-config)
// A section `key:` groups the keys of a member struct (at(&S::spp)) or of the struct itself (whole: the rover's
// `input:`); the fusion's keys are flat under `fusion:` and reach its per-piece structs by nested member pointers.
//
// A codec converts between a member of type T and its YAML form:
//   using Yaml = ...;                                        one of the types YamlMap::get reads
//   Yaml to(const T& member) const;                          the member in YAML form (the start value when reading)
//   void from(const Yaml& value, T& member, Reading&) const;  back into the member; Reading::fail() if it is bad
// and may declare
//   bool omitted(const T& member) const;       not printed when true (an optional left unset)
//   static constexpr bool kOnlyIfPresent = true;  read only when the key is in the file
//   static constexpr bool kQuoted = true;          printed in double quotes
//   void print(const T& member, Printer&) const;   printed otherwise than `to` (numbers read as text)

#include <concepts>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include "canyon/config/yaml_reader.hpp"
#include "canyon/core/constants.hpp"
#include "canyon/core/satellite.hpp"

namespace canyon::config {

/// How numbers are printed: 12 significant digits (process, rover and base configurations: 0.99, not
/// 0.98999999999999999; 15 deg, not 14.999999999999998) or the shortest text that reads back as the same double
/// (scenarios, which must reproduce a simulation exactly).
enum class Numbers { Digits12, Shortest };

/// One key as describe_keys() gives it.
struct KeyDescription {
  std::string path;           ///< dotted key path ("rtk.elevation_mask_deg")
  std::string unit;           ///< as the shipped files write it; empty: none
  std::string default_value;  ///< the default in YAML ("15", "[G, R, E, C, J]"); empty: unset (an optional key)
  std::string doc;            ///< one line
};

/// The keys as a table, one line each: key, unit, default, doc.
[[nodiscard]] std::string format_descriptions(const std::vector<KeyDescription>& keys);

/// `path` relative to the folder of the YAML `file` it was read from (absolute paths, and "" stay as they are).
[[nodiscard]] std::string resolve_path(const std::string& path, const std::string& file);

/// The shortest decimal text that reads back as the same double, its integer part written out (600, not 6e+02).
[[nodiscard]] std::string shortest_number(double value);

/// A codec's view of the key it reads: a failure is recorded in the map, naming the file, the line and the key path.
class Reading {
 public:
  Reading(YamlMap& map, std::string key) : map_(map), key_(std::move(key)) {}
  /// Records "'path.key' <message>" at the key's line.
  void fail(const std::string& message);
  [[nodiscard]] bool failed() const { return failed_; }
  /// The YAML file being read (relative paths are relative to its folder); may be empty.
  [[nodiscard]] const std::string& file() const { return map_.file(); }

 private:
  YamlMap& map_;
  std::string key_;
  bool failed_ = false;
};

/// Writes keys and values to a YAML emitter, numbers in the given style.
class Printer {
 public:
  Printer(YAML::Emitter& out, Numbers numbers);
  void key(const std::string& key);
  void begin_map();
  void end_map();
  void value(double v);
  void value(int v);
  void value(bool v);
  void value(const std::string& v, bool quoted = false);
  void value(const std::vector<std::string>& v);
  void value(const std::vector<double>& v);
  void value(const std::vector<std::vector<double>>& v);

 private:
  void number(double v);
  YAML::Emitter& out_;
  Numbers numbers_;
};

template <typename S>
struct Entry;
/// The keys of an options struct S, in order.
template <typename S>
using Table = std::vector<Entry<S>>;

/// The member reached by a path of member pointers: at(&S::a, &A::b)(s) is s.a.b (at() is s itself).
template <typename... Members>
constexpr auto at(Members... path) {
  return [path...](auto& s) -> auto& {
    return (s.*....*path);
  };
}
/// The struct itself: a section grouping keys of the same struct, or a codec that needs several members.
inline constexpr auto whole = [](auto& s) -> auto& {
  return s;
};

/// The member as it is (double, int, bool, text, a list of texts or of numbers).
struct Plain {};
template <typename T>
struct Same {
  using Yaml = T;
  [[nodiscard]] T to(const T& v) const { return v; }
  void from(const T& value, T& v, Reading& /*reading*/) const { v = value; }
};

namespace detail {
template <typename C>
constexpr bool only_if_present() {
  if constexpr (requires { C::kOnlyIfPresent; }) {
    return C::kOnlyIfPresent;
  } else {
    return false;
  }
}
template <typename C>
constexpr bool quoted() {
  if constexpr (requires { C::kQuoted; }) {
    return C::kQuoted;
  } else {
    return false;
  }
}
template <typename C, typename T>
bool omitted(const C& codec, const T& member) {
  if constexpr (requires { codec.omitted(member); }) {
    return codec.omitted(member);
  } else {
    return false;
  }
}
template <typename C, typename T>
void print_value(const C& codec, const T& member, Printer& printer) {
  if constexpr (requires { codec.print(member, printer); }) {
    codec.print(member, printer);
  } else if constexpr (std::is_same_v<typename C::Yaml, std::string>) {
    printer.value(codec.to(member), quoted<C>());
  } else {
    printer.value(codec.to(member));
  }
}
/// The value as a one-line YAML text (describe_keys()).
template <typename C, typename T>
std::string value_text(const C& codec, const T& member, Numbers numbers) {
  YAML::Emitter out;
  Printer printer(out, numbers);
  print_value(codec, member, printer);
  return out.c_str();
}
}  // namespace detail

template <typename S>
void read_keys(const Table<S>& table, YamlMap& map, S& s);
template <typename S>
void print_keys(const Table<S>& table, const S& s, Printer& printer);
template <typename S>
[[nodiscard]] bool equal_keys(const Table<S>& table, const S& a, const S& b);
template <typename S>
void describe_keys(const Table<S>& table, const S& s, const std::string& prefix, Numbers numbers,
                   std::vector<KeyDescription>& out);

/// One key of S (a value or a section), by its operations.
template <typename S>
struct Entry {
  std::string key;
  std::string unit;
  std::string doc;
  std::function<void(S&, YamlMap&)> read;
  std::function<void(const S&, Printer&)> print;  ///< key and value (nothing when omitted)
  std::function<bool(const S&, const S&)> equal;
  std::function<void(const S&, const std::string& prefix, Numbers, std::vector<KeyDescription>&)> describe;

  Entry() = default;

  /// A key: `access` reaches the member (at(...), whole), `codec` converts it (Plain: taken as it is).
  template <typename Access, typename Codec = Plain>
  Entry(std::string key_, std::string unit_, std::string doc_, Access access, [[maybe_unused]] Codec codec = {})
      : key(std::move(key_)), unit(std::move(unit_)), doc(std::move(doc_)) {
    using T = std::remove_cvref_t<decltype(access(std::declval<S&>()))>;
    using C = std::conditional_t<std::is_same_v<Codec, Plain>, Same<T>, Codec>;
    C c{};
    if constexpr (!std::is_same_v<Codec, Plain>) c = std::move(codec);
    read = [k = key, access, c](S& s, YamlMap& map) {
      if constexpr (detail::only_if_present<C>()) {
        if (!map.has(k)) return;
      }
      T& member = access(s);
      typename C::Yaml value = c.to(member);
      map.get(k, value);
      Reading reading(map, k);
      c.from(value, member, reading);
    };
    print = [k = key, access, c](const S& s, Printer& printer) {
      const T& member = access(s);
      if (detail::omitted(c, member)) return;
      printer.key(k);
      detail::print_value(c, member, printer);
    };
    equal = [access, c](const S& a, const S& b) {
      const T& x = access(a);
      const T& y = access(b);
      if constexpr (std::equality_comparable<T> && !std::is_same_v<T, S>) {
        return x == y;
      } else {
        if (detail::omitted(c, x) || detail::omitted(c, y)) return detail::omitted(c, x) == detail::omitted(c, y);
        return c.to(x) == c.to(y);
      }
    };
    describe = [k = key, u = unit, d = doc, access, c](const S& s, const std::string& prefix, Numbers numbers,
                                                       std::vector<KeyDescription>& out) {
      const T& member = access(s);
      out.push_back({prefix + k, u, detail::omitted(c, member) ? "" : detail::value_text(c, member, numbers), d});
    };
  }

  /// A section `key:` holding the keys of `table` for the member `access` reaches (whole: the struct itself).
  template <typename Access, typename M>
  Entry(std::string key_, std::string doc_, Access access, const Table<M>& table)
      : key(std::move(key_)), doc(std::move(doc_)) {
    const auto keys = std::make_shared<const Table<M>>(table);
    read = [k = key, access, keys](S& s, YamlMap& map) {
      YamlMap section = map.sub(k);
      read_keys(*keys, section, access(s));
    };
    print = [k = key, access, keys](const S& s, Printer& printer) {
      printer.key(k);
      printer.begin_map();
      print_keys(*keys, access(s), printer);
      printer.end_map();
    };
    equal = [access, keys](const S& a, const S& b) { return equal_keys(*keys, access(a), access(b)); };
    describe = [k = key, access, keys](const S& s, const std::string& prefix, Numbers numbers,
                                       std::vector<KeyDescription>& out) {
      describe_keys(*keys, access(s), prefix + k + ".", numbers, out);
    };
  }
};

/// A section that is accepted and ignored (a scenario's `truth:`, written by canyon simulate).
template <typename S>
Entry<S> ignored_section(const std::string& key) {
  Entry<S> e;
  e.key = key;
  e.read = [key](S& /*s*/, YamlMap& map) { (void)map.sub(key); };
  e.print = [](const S& /*s*/, Printer& /*printer*/) {};
  e.equal = [](const S& /*a*/, const S& /*b*/) { return true; };
  e.describe = [](const S& /*s*/, const std::string& /*prefix*/, Numbers /*numbers*/,
                  std::vector<KeyDescription>& /*out*/) {};
  return e;
}

template <typename S>
void read_keys(const Table<S>& table, YamlMap& map, S& s) {
  for (const Entry<S>& e : table) e.read(s, map);
  map.reject_unknown_keys();
}

template <typename S>
void print_keys(const Table<S>& table, const S& s, Printer& printer) {
  for (const Entry<S>& e : table) e.print(s, printer);
}

template <typename S>
bool equal_keys(const Table<S>& table, const S& a, const S& b) {
  for (const Entry<S>& e : table) {
    if (!e.equal(a, b)) return false;
  }
  return true;
}

template <typename S>
void describe_keys(const Table<S>& table, const S& s, const std::string& prefix, Numbers numbers,
                   std::vector<KeyDescription>& out) {
  for (const Entry<S>& e : table) e.describe(s, prefix, numbers, out);
}

/// The struct as a YAML document (a map of its keys), ending with a newline.
template <typename S>
std::string yaml_text(const Table<S>& table, const S& s, Numbers numbers) {
  YAML::Emitter out;
  Printer printer(out, numbers);
  printer.begin_map();
  print_keys(table, s, printer);
  printer.end_map();
  return std::string(out.c_str()) + "\n";
}

/// Every key of the table with its default: its value in `defaults` (a default-constructed struct).
template <typename S>
std::vector<KeyDescription> describe_keys(const Table<S>& table, const S& defaults, Numbers numbers) {
  std::vector<KeyDescription> out;
  describe_keys(table, defaults, "", numbers, out);
  return out;
}

// ---------------------------------------------------------------------------------------------------------------
// Codecs used by several tables.

/// Radians in the struct, degrees in YAML (the arithmetic of every parser and printer before the tables).
struct Degrees {
  using Yaml = double;
  [[nodiscard]] double to(double rad) const { return rad * core::kRadToDeg; }
  void from(double deg, double& rad, Reading& /*reading*/) const { rad = deg * core::kDegToRad; }
};

/// "must be a, b or c, not 'x'".
[[nodiscard]] std::string must_be_one_of(const std::vector<std::string>& names, const std::string& value);

/// An enumeration (or a bool) by name. The names are listed in errors in their order; the first name of a value is
/// the one printed; `aliases` are also read.
template <typename E>
struct Names {
  using Yaml = std::string;
  std::vector<std::pair<E, std::string>> names;
  std::vector<std::pair<E, std::string>> aliases = {};

  [[nodiscard]] std::string to(E v) const {
    for (const auto& [value, name] : names) {
      if (value == v) return name;
    }
    return "?";
  }
  void from(const std::string& text, E& v, Reading& reading) const {
    for (const auto* list : {&names, &aliases}) {
      for (const auto& [value, name] : *list) {
        if (name == text) {
          v = value;
          return;
        }
      }
    }
    std::vector<std::string> listed;
    listed.reserve(names.size());
    for (const auto& n : names) listed.push_back(n.second);
    reading.fail(must_be_one_of(listed, text));
  }
};

/// The names of `values` as `name_of` gives them (the enumeration's own name function).
template <typename E, typename NameOf>
Names<E> names_of(std::initializer_list<E> values, NameOf name_of) {
  Names<E> n;
  for (const E v : values) n.names.emplace_back(v, std::string(name_of(v)));
  return n;
}

/// A count (std::size_t) as an integer; a negative number reads as 0 (validate() names the rule).
struct Count {
  using Yaml = int;
  [[nodiscard]] int to(std::size_t n) const { return static_cast<int>(n); }
  void from(int value, std::size_t& n, Reading& /*reading*/) const {
    n = value < 0 ? 0 : static_cast<std::size_t>(value);
  }
};

/// A file path, relative to the YAML file's folder.
struct Path {
  using Yaml = std::string;
  [[nodiscard]] std::string to(const std::string& path) const { return path; }
  void from(const std::string& value, std::string& path, Reading& reading) const {
    path = resolve_path(value, reading.file());
  }
};

/// A list of file paths (one may be written without brackets), each relative to the YAML file's folder.
struct Paths {
  using Yaml = std::vector<std::string>;
  [[nodiscard]] Yaml to(const Yaml& paths) const { return paths; }
  void from(const Yaml& value, Yaml& paths, Reading& reading) const;
};

/// Satellites as text ([G05, E11]).
struct Satellites {
  using Yaml = std::vector<std::string>;
  [[nodiscard]] Yaml to(const std::vector<core::SatelliteId>& sats) const;
  void from(const Yaml& value, std::vector<core::SatelliteId>& sats, Reading& reading) const;
};

/// Constellations as letters ([G, R, E]); `allowed` names the letters in the error.
struct Systems {
  using Yaml = std::vector<std::string>;
  std::string allowed = "G, R, E, C, J";
  [[nodiscard]] Yaml to(const core::ConstellationFlags& flags) const { return flags.letters(); }
  void from(const Yaml& value, core::ConstellationFlags& flags, Reading& reading) const;
};

/// A 3-vector as [x, y, z]; `rule` is the error for any other length.
struct Vector3 {
  using Yaml = std::vector<double>;
  std::string rule = "must be [x, y, z]";
  [[nodiscard]] Yaml to(const Eigen::Vector3d& v) const { return {v.x(), v.y(), v.z()}; }
  void from(const Yaml& value, Eigen::Vector3d& v, Reading& reading) const;
};

/// A std::optional member: printed only when set, read only when the key is present, by the codec of its value.
template <typename C>
struct Optional {
  using Yaml = typename C::Yaml;
  static constexpr bool kOnlyIfPresent = true;
  static constexpr bool kQuoted = detail::quoted<C>();
  C inner;

  template <typename U>
  [[nodiscard]] Yaml to(const std::optional<U>& v) const {
    return v ? inner.to(*v) : Yaml{};
  }
  template <typename U>
  [[nodiscard]] bool omitted(const std::optional<U>& v) const {
    return !v.has_value();
  }
  template <typename U>
  void print(const std::optional<U>& v, Printer& printer) const {
    detail::print_value(inner, *v, printer);
  }
  template <typename U>
  void from(const Yaml& value, std::optional<U>& v, Reading& reading) const {
    if (v) {
      inner.from(value, *v, reading);
      return;
    }
    U u;
    inner.from(value, u, reading);
    if (!reading.failed()) v = u;
  }
};

}  // namespace canyon::config
