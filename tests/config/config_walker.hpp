// Walks bad values through every numeric key of a program's config (tests only): each key of a
// config struct (found through its visit() member, nested structs and lists included) is set in
// turn to NaN, +-infinity, a negative value, zero and 1e9, and each pair of keys that bound a range
// (x_min / x_max, min_range_m / max_range_m, an interval's [lo, hi]) is inverted; the config is
// written over the program's shipped one and the program run on a small input. The program must
// either refuse the config (exit 2, naming the key and the file) or run to its normal end: no
// signal, no hang, no other exit code.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "config.hpp"

namespace traverse::test {

// A numeric key of a config: its path ("map.resolution_m", "corridors[0].end_a.at") and value.
struct NumericKey {
  std::string path;
  double value = 0.0;
  bool integral = false;
};

// The visitor that lists them.
class NumericKeyLister {
 public:
  explicit NumericKeyLister(std::string prefix = "") : prefix_(std::move(prefix)) {}
  template <class T>
  void operator()(const char* key, T& value) {
    add(prefix_ + key, value);
  }
  std::vector<NumericKey> keys;

 private:
  template <class T>
  void add(const std::string& path, T& value) {
    if constexpr (std::is_same_v<T, bool> || std::is_same_v<T, std::string>) {
      return;
    } else if constexpr (std::is_arithmetic_v<T>) {
      keys.push_back({path, static_cast<double>(value), std::is_integral_v<T>});
    } else if constexpr (config_detail::is_vector<T>::value) {
      for (std::size_t i = 0; i < value.size(); ++i)
        add(path + "[" + std::to_string(i) + "]", value[i]);
    } else {
      NumericKeyLister nested(path + ".");
      value.visit(nested);
      keys.insert(keys.end(), nested.keys.begin(), nested.keys.end());
    }
  }
  std::string prefix_;
};

// Every numeric key of `config` (as loaded from the shipped file, so that its lists count).
template <class Config>
std::vector<NumericKey> numeric_keys(Config config) {
  NumericKeyLister lister;
  config.visit(lister);
  return lister.keys;
}

// One config to try: keys set to values (YAML scalars).
struct Assignment {
  std::string path, value;
};
struct Trial {
  std::string what;  // e.g. "map.resolution_m = .nan"
  std::vector<Assignment> set;
};

// The other bound of a range key, if the config has it: min <-> max in the last path component,
// or the other end of a two-number list ([0] <-> [1]).
inline std::optional<std::string> partner_of(const std::string& path,
                                             const std::vector<NumericKey>& keys) {
  const auto exists = [&](const std::string& p) {
    for (const auto& k : keys) {
      if (k.path == p) return true;
    }
    return false;
  };
  const std::size_t dot = path.rfind('.');
  const std::size_t start = dot == std::string::npos ? 0 : dot + 1;
  for (const auto& [a, b] : {std::pair<std::string, std::string>{"min", "max"}, {"max", "min"}}) {
    const std::size_t at = path.find(a, start);
    if (at == std::string::npos) continue;
    std::string other = path;
    other.replace(at, a.size(), b);
    if (exists(other)) return other;
  }
  if (path.size() > 3 && path.compare(path.size() - 3, 3, "[0]") == 0) {
    const std::string other = path.substr(0, path.size() - 3) + "[1]";
    if (exists(other)) return other;
  }
  return std::nullopt;
}

inline std::string number_text(double v, bool integral) {
  if (integral) return std::to_string(static_cast<long long>(v));
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// NaN, +-infinity, a negative value, zero and 1e9 for every key; each range inverted once.
inline std::vector<Trial> trials(const std::vector<NumericKey>& keys) {
  std::vector<Trial> out;
  for (const NumericKey& k : keys) {
    for (const char* v : {".nan", ".inf", "-.inf"})
      out.push_back({k.path + " = " + v, {{k.path, v}}});
    const double negative = -std::max(std::abs(k.value), 1.0);
    out.push_back({k.path + " negative", {{k.path, number_text(negative, k.integral)}}});
    out.push_back({k.path + " = 0", {{k.path, "0"}}});
    out.push_back({k.path + " huge", {{k.path, k.integral ? "1000000000" : "1e9"}}});
    if (const auto other = partner_of(k.path, keys); other && k.path < *other) {
      double other_value = 0.0;
      for (const auto& o : keys) {
        if (o.path == *other) other_value = o.value;
      }
      out.push_back({k.path + " and " + *other + " swapped",
                     {{k.path, number_text(other_value, k.integral)},
                      {*other, number_text(k.value, k.integral)}}});
    }
  }
  return out;
}

// One step of a key path: a map key, or (key empty) a list index.
struct PathStep {
  std::string key;
  int index = 0;
};

inline std::vector<PathStep> path_steps(const std::string& path) {
  std::vector<PathStep> steps;
  std::stringstream ss(path);
  for (std::string part; std::getline(ss, part, '.');) {
    const std::size_t open = part.find('[');
    steps.push_back({part.substr(0, open), 0});
    for (std::size_t at = open; at != std::string::npos; at = part.find('[', at + 1)) {
      steps.push_back({"", std::stoi(part.substr(at + 1))});
    }
  }
  return steps;
}

// Sets `value` (a YAML scalar) at steps[i..] below `node`, creating maps on the way. Nodes are
// passed by value and never assigned to one another (yaml-cpp would alias them).
inline void set_at(YAML::Node node, const std::vector<PathStep>& steps, std::size_t i,
                   const std::string& value) {
  const PathStep& s = steps[i];
  if (i + 1 == steps.size()) {
    if (s.key.empty()) {
      node[s.index] = YAML::Load(value);
    } else {
      node[s.key] = YAML::Load(value);
    }
    return;
  }
  if (s.key.empty()) {
    set_at(node[s.index], steps, i + 1, value);
  } else {
    set_at(node[s.key], steps, i + 1, value);
  }
}

inline void set_path(YAML::Node root, const std::string& path, const std::string& value) {
  set_at(root, path_steps(path), 0, value);
}

struct RunResult {
  int exit_code = -1;  // 128 + signal when killed (137: the time limit)
  std::string err;     // what it printed (standard output and error)
};

inline RunResult run_command(const std::string& command, const std::string& err_file) {
  RunResult r;
  const int status = std::system((command + " >" + err_file + " 2>&1").c_str());
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream in(err_file);
  r.err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return r;
}

// A program to walk: run as `program --config FILE` followed by each of `inputs` (one run per
// input for a config it accepts), from the repository root.
struct WalkCase {
  std::string program;              // in build/bin
  std::string shipped_config;       // the base every trial is written over
  std::vector<std::string> inputs;  // argument lists (e.g. "--replay IN.lcmlog")
  std::string work_dir;             // for the trial configs and outputs
  int time_limit_s = 60;
  // A program that runs until stopped gets SIGINT after this long (0: it ends by itself).
  double stop_after_s = 0.0;
  // Keys under a prefix walked otherwise: on the smallest inputs that exercise them (instead of
  // `inputs`), with `set` added to every trial and to the shipped config's run (e.g. the kind of
  // frontend whose keys they are). The first part whose prefix a key's path starts with.
  struct Part {
    std::vector<std::string> prefixes;  // e.g. "icp."
    std::vector<std::string> inputs;
    std::vector<Assignment> set;
  };
  std::vector<Part> parts;
};

struct WalkSummary {
  int trials = 0, refused = 0, ran = 0;
  int runs = 0;  // programs started
};

// Runs every trial of Config's keys (see the header); GoogleTest failures name the trial.
template <class Config>
WalkSummary walk_config(const WalkCase& c) {
  WalkSummary summary;
  Config shipped;
  load_config(c.shipped_config, shipped);
  const std::vector<NumericKey> keys = numeric_keys(shipped);
  EXPECT_FALSE(keys.empty()) << c.shipped_config;
  const std::string program = std::string(TRAVERSE_BIN_DIR) + "/" + c.program;
  const std::string config_file = c.work_dir + "/" + c.program + "-trial.yaml";
  const std::string err_file = c.work_dir + "/" + c.program + "-trial.err";
  // Where each trial runs: the part its first key falls in, or the whole inputs.
  const WalkCase::Part whole{{}, c.inputs, {}};
  const auto part_of = [&](const Trial& t) -> const WalkCase::Part& {
    for (const WalkCase::Part& p : c.parts) {
      for (const std::string& prefix : p.prefixes) {
        if (t.set.front().path.rfind(prefix, 0) == 0) return p;
      }
    }
    return whole;
  };
  const auto write_config = [&](const std::vector<Assignment>& base, const Trial* t) {
    YAML::Node root = YAML::LoadFile(c.shipped_config);
    for (const Assignment& a : base) set_path(root, a.path, a.value);
    if (t) {
      for (const Assignment& a : t->set) set_path(root, a.path, a.value);
    }
    std::ofstream out(config_file);
    out << YAML::Dump(root) << "\n";
  };
  const auto run = [&](const std::string& input) {
    std::string command = "timeout -s KILL " + std::to_string(c.time_limit_s) + " ";
    if (c.stop_after_s > 0.0) {
      command += "timeout --preserve-status -s INT " + std::to_string(c.stop_after_s) + " ";
    }
    return run_command(command + program + " --config " + config_file + " " + input, err_file);
  };
  // The shipped config itself runs on every input of every part (or the walk shows nothing).
  std::vector<const WalkCase::Part*> all_parts{&whole};
  for (const WalkCase::Part& p : c.parts) all_parts.push_back(&p);
  for (const WalkCase::Part* p : all_parts) {
    write_config(p->set, nullptr);
    for (const std::string& input : p->inputs) {
      const RunResult r = run(input);
      EXPECT_EQ(r.exit_code, 0) << c.program << " as shipped on " << input << ":\n" << r.err;
      ++summary.runs;
    }
  }
  for (const Trial& t : trials(keys)) {
    ++summary.trials;
    const WalkCase::Part& part = part_of(t);
    const std::vector<std::string>& inputs = part.inputs;
    write_config(part.set, &t);
    // Refused at start (no input needed): exit 2 naming a key it set and the file.
    const RunResult r = run(inputs[0]);
    ++summary.runs;
    if (r.exit_code == 2) {
      ++summary.refused;
      bool named = false;
      // The key by its path, or the list element it is in ("across[1]" for "across[1][0]"); a
      // value refused against another key's ("must exceed min_range_m") by that other key's
      // path and its own name.
      for (const Assignment& a : t.set) {
        for (std::string key = a.path; !named && !key.empty();) {
          named = r.err.find("'" + key + "'") != std::string::npos;
          const std::size_t open = key.rfind('[');
          key = open != std::string::npos && key.back() == ']' ? key.substr(0, open) : "";
        }
        const std::string name = a.path.substr(a.path.rfind('.') + 1);
        named = named || (r.err.find("key '") != std::string::npos &&
                          r.err.find(" " + name) != std::string::npos);
      }
      EXPECT_TRUE(named) << c.program << " " << t.what << ": refused without naming the key:\n"
                         << r.err;
      EXPECT_NE(r.err.find(config_file), std::string::npos)
          << c.program << " " << t.what << ": refused without naming the file:\n"
          << r.err;
      continue;
    }
    ++summary.ran;
    EXPECT_EQ(r.exit_code, 0) << c.program << " " << t.what << " on " << inputs[0] << ":\n"
                              << r.err;
    if (r.exit_code != 0) continue;
    for (std::size_t i = 1; i < inputs.size(); ++i) {
      const RunResult ri = run(inputs[i]);
      ++summary.runs;
      EXPECT_EQ(ri.exit_code, 0) << c.program << " " << t.what << " on " << inputs[i] << ":\n"
                                 << ri.err;
    }
  }
  std::printf("%s: %zu numeric keys, %d trials: %d refused, %d ran; %d program runs\n",
              c.program.c_str(), keys.size(), summary.trials, summary.refused, summary.ran,
              summary.runs);
  return summary;
}

}  // namespace traverse::test
