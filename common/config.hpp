// Configuration from YAML into plain structs whose defaults are written in the struct.
//
// A config struct lists its keys once, in a `visit` member:
//
//   struct MatcherConfig {
//     double resolution_m = 0.05;
//     int levels = 3;
//     template <class V> void visit(V& v) { v("resolution_m", resolution_m); v("levels", levels); }
//   };
//
// Members may be bool, integers, double, std::string, std::vector of those, or nested structs
// with their own `visit`. Loading fails with a ConfigError naming the file and the full key path
// when a key is unknown, has the wrong type, or the file is missing or not YAML. Keys absent from
// the file keep their defaults.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <concepts>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace traverse {

// Exit code of every program when its configuration is bad.
inline constexpr int kConfigErrorExitCode = 2;

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace config_detail {

template <class T>
struct is_vector : std::false_type {};
template <class T>
struct is_vector<std::vector<T>> : std::true_type {};

std::string type_name_of(const YAML::Node& n);

class Reader {
 public:
  Reader(const YAML::Node& node, std::string file, std::string prefix)
      : node_(node), file_(std::move(file)), prefix_(std::move(prefix)) {
    check_is_mapping();
  }

  // Called by the struct's visit(): reads one key if present.
  template <class T>
  void operator()(const char* key, T& value) {
    used_.push_back(key);
    const YAML::Node& node = node_;  // const: a look-up must not add the key
    const YAML::Node child = node[key];
    if (!child) return;
    read(child, prefix_ + key, value);
  }

  // After visit(): every key in the file must have been used.
  void check_unknown_keys() const;

 private:
  template <class T>
  void read(const YAML::Node& n, const std::string& path, T& value) {
    if constexpr (std::is_class_v<T> && !std::is_same_v<T, std::string> && !is_vector<T>::value) {
      if (!n.IsMap()) fail(path, "a mapping of keys", n);
      Reader nested(n, file_, path + ".");
      value.visit(nested);
      nested.check_unknown_keys();
    } else if constexpr (is_vector<T>::value) {
      if (!n.IsSequence()) fail(path, "a list", n);
      T out;
      for (std::size_t i = 0; i < n.size(); ++i) {
        typename T::value_type item{};
        read(n[i], path + "[" + std::to_string(i) + "]", item);
        out.push_back(std::move(item));
      }
      value = std::move(out);
    } else {
      if (!n.IsScalar()) fail(path, expected_name<T>(), n);
      try {
        value = n.as<T>();
      } catch (const YAML::Exception&) {
        fail(path, expected_name<T>(), n);
      }
      // .inf and .nan are valid YAML numbers, but no setting means them: a range check of the
      // form "at least x" would let them through.
      if constexpr (std::is_floating_point_v<T>) {
        if (!std::isfinite(value)) fail(path, expected_name<T>(), n);
      }
    }
  }

  template <class T>
  static const char* expected_name() {
    if constexpr (std::is_same_v<T, bool>)
      return "true or false";
    else if constexpr (std::is_integral_v<T>)
      return "an integer";
    else if constexpr (std::is_floating_point_v<T>)
      return "a finite number";
    else
      return "a string";
  }

  void check_is_mapping() const;
  [[noreturn]] void fail(const std::string& path, const char* expected,
                         const YAML::Node& got) const;

  YAML::Node node_;
  std::string file_;
  std::string prefix_;
  std::vector<std::string> used_;
};

YAML::Node load_file(const std::string& path);
YAML::Node load_string(const std::string& text, const std::string& name);

// Ends the ordinary look-up of `validate` here (with a function no config matches), so that the
// call below finds the stage's validate(const XConfig&) by argument-dependent look-up, whatever
// else is named validate in namespace traverse.
struct NoValidate {};
void validate(NoValidate);

// The stage's validate(config), or nullopt for a config without one.
template <class Config>
std::optional<std::string> validate_stage(const Config& config) {
  if constexpr (requires {
                  { validate(config) } -> std::convertible_to<std::optional<std::string>>;
                }) {
    return validate(config);
  } else {
    return std::nullopt;
  }
}

}  // namespace config_detail

// Checks the values of a loaded config, naming each bad one by its key path. A stage's
// `validate(const XConfig&)` runs the checks of its struct (and of nested structs, with
// `nested("key")`) and returns `problem()`; the process start turns a problem into a ConfigError
// naming the file, so every program refuses a config it cannot run with before it starts.
//
//   std::optional<std::string> validate(const MatcherConfig& c) {
//     ConfigCheck check;
//     check.positive("resolution_m", c.resolution_m);
//     check.in_range("levels", c.levels, 1, 8);
//     check.require(c.max_range_m > c.min_range_m, "max_range_m", "must exceed min_range_m");
//     return check.problem();
//   }
class ConfigCheck {
 public:
  explicit ConfigCheck(std::string prefix = "") : prefix_(std::move(prefix)) {}

  // `ok` or the key is reported with `what` ("must be positive").
  void require(bool ok, const std::string& key, const std::string& what) {
    if (!ok && !problem_) problem_ = "key '" + prefix_ + key + "' " + what;
  }
  template <class T>
  void positive(const std::string& key, T value) {
    require(value > T{0}, key, "must be positive, got " + show(value));
  }
  template <class T>
  void not_negative(const std::string& key, T value) {
    require(value >= T{0}, key, "must not be negative, got " + show(value));
  }
  template <class T>
  void in_range(const std::string& key, T value, T lo, T hi) {
    require(value >= lo && value <= hi, key,
            "must be in [" + show(lo) + ", " + show(hi) + "], got " + show(value));
  }
  void not_empty(const std::string& key, const std::string& value) {
    require(!value.empty(), key, "must not be empty");
  }
  // A nested struct's problem, its keys prefixed with `key.`.
  void nested(const std::string& key, const std::optional<std::string>& nested_problem) {
    if (nested_problem && !problem_) problem_ = insert_prefix(prefix_ + key + ".", *nested_problem);
  }
  // The first problem found, or nullopt when every check passed.
  const std::optional<std::string>& problem() const { return problem_; }

 private:
  template <class T>
  static std::string show(T value) {
    if constexpr (std::is_floating_point_v<T>) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%g", static_cast<double>(value));
      return buf;
    } else {
      return std::to_string(value);
    }
  }
  // "key 'a' ..." becomes "key 'prefix.a' ...".
  static std::string insert_prefix(const std::string& prefix, const std::string& problem) {
    const std::string head = "key '";
    if (problem.rfind(head, 0) == 0) return head + prefix + problem.substr(head.size());
    return prefix + problem;
  }

  std::string prefix_;
  std::optional<std::string> problem_;
};

// Loads `path` into `config`, throwing ConfigError (naming the key and the file) on any problem.
template <class Config>
void load_config(const std::string& path, Config& config) {
  config_detail::Reader reader(config_detail::load_file(path), path, "");
  config.visit(reader);
  reader.check_unknown_keys();
}

// Same from YAML text; `name` stands in for the file name in errors (tests, embedded defaults).
template <class Config>
void load_config_text(const std::string& text, const std::string& name, Config& config) {
  config_detail::Reader reader(config_detail::load_string(text, name), name, "");
  config.visit(reader);
  reader.check_unknown_keys();
}

}  // namespace traverse
