// Every program answers --help; every process stops with exit 2 on an unknown config key and
// names it. Programs are found in the build's bin/, so new ones are covered without edits here.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <set>

#include "graph_test_util.hpp"

namespace traverse::graph_test {
namespace {

// Programs that are not processes of the graph (no --config/--lcm-url contract). Everything else
// in bin/traverse-* is a process.
const std::set<std::string> kTools = {
    "validate",      "launch",      "frontend-bench",    "pgo",
    "pgo-ceres",     "cloud-eval",  "densifier-compare", "mapper-bench",
    "preview-bench", "sim-realism", "annotator-eval",    "export"};

// Processes that need inputs besides a config to start at all get them here; the config must
// still be checked, and named when wrong.
const std::map<std::string, std::string> kRequiredArgs = {
    {"sim", "--world configs/worlds/corridor.yaml --route configs/routes/corridor-return.yaml"},
    {"record", "/tmp/traverse_programs_test_never_written.lcmlog"},
};

TEST(Programs, ThereAreSome) {
  const auto programs = traverse_programs();
  EXPECT_GE(programs.size(), 3u);
  for (const char* required : {"carmen", "launch", "monitor", "validate"}) {
    EXPECT_NE(std::find(programs.begin(), programs.end(), required), programs.end()) << required;
  }
}

TEST(Programs, EveryProgramAnswersHelp) {
  for (const auto& name : traverse_programs()) {
    const auto r = run(bin_dir() + "/traverse-" + name + " --help", 20);
    EXPECT_EQ(r.exit_code, 0) << "traverse-" << name << " --help:\n" << r.output;
    EXPECT_NE(r.output.find("--"), std::string::npos)
        << "traverse-" << name << " prints no options";
  }
}

TEST(Programs, EveryProcessRejectsAnUnknownConfigKeyNamingIt) {
  const auto dir = temp_dir("config");
  const auto config = (dir / "bad.yaml").string();
  std::ofstream(config) << "surely_not_a_key_42: 1\n";
  int port = 31400;  // private, in case a process connects before reading its config
  for (const auto& name : traverse_programs()) {
    if (kTools.count(name)) continue;
    const std::string url = "udpm://239.255.76.67:" + std::to_string(port++) + "?ttl=0";
    const auto extra = kRequiredArgs.find(name);
    const auto r =
        run(bin_dir() + "/traverse-" + name + " --config " + config + " --lcm-url \"" + url +
                "\" " + (extra == kRequiredArgs.end() ? "" : extra->second) + " < /dev/null",
            20);
    EXPECT_EQ(r.exit_code, 2) << "traverse-" << name << ":\n" << r.output;
    EXPECT_NE(r.output.find("surely_not_a_key_42"), std::string::npos)
        << "traverse-" << name << " does not name the key:\n"
        << r.output;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::graph_test
