#include "config.hpp"

#include <algorithm>
#include <filesystem>

namespace traverse::config_detail {

std::string type_name_of(const YAML::Node& n) {
  if (n.IsMap()) return "a mapping";
  if (n.IsSequence()) return "a list";
  if (n.IsNull()) return "nothing";
  return "'" + n.Scalar() + "'";
}

void Reader::check_is_mapping() const {
  if (node_.IsNull()) return;  // empty file or section: all defaults
  if (node_.IsMap()) {
    // YAML forbids a key twice in one mapping, but the parser keeps both and a look-up finds the
    // first: the second would be ignored without a word.
    std::vector<std::string> seen;
    for (const auto& kv : node_) {
      if (!kv.first.IsScalar()) {
        throw ConfigError(file_ + ": " + (prefix_.empty() ? std::string("top level") : prefix_) +
                          " has a key that is not a name but " + type_name_of(kv.first));
      }
      const std::string key = kv.first.Scalar();
      if (std::find(seen.begin(), seen.end(), key) != seen.end()) {
        throw ConfigError(file_ + ": key '" + prefix_ + key + "' appears twice");
      }
      seen.push_back(key);
    }
    return;
  }
  throw ConfigError(file_ + ": " + (prefix_.empty() ? std::string("top level") : prefix_) +
                    " must be a mapping of keys, got " + type_name_of(node_));
}

void Reader::check_unknown_keys() const {
  if (node_.IsNull()) return;
  for (const auto& kv : node_) {
    const std::string key = kv.first.as<std::string>();
    if (std::find(used_.begin(), used_.end(), key) == used_.end()) {
      throw ConfigError(file_ + ": unknown key '" + prefix_ + key + "'");
    }
  }
}

void Reader::fail(const std::string& path, const char* expected, const YAML::Node& got) const {
  throw ConfigError(file_ + ": key '" + path + "' expects " + expected + ", got " +
                    type_name_of(got));
}

YAML::Node load_file(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw ConfigError("config file not found: " + path);
  }
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw ConfigError(path + ": not valid YAML: " + e.what());
  }
}

YAML::Node load_string(const std::string& text, const std::string& name) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(name + ": not valid YAML: " + e.what());
  }
}

}  // namespace traverse::config_detail
