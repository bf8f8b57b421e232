// Every process's config walked with bad values (config_walker.hpp): NaN, infinities, negative
// values, zero, 1e9 and inverted ranges through every numeric key, each program run on a small
// input made here from the sample log (logs/) and, for the CARMEN driver and the frontend's sparse
// path, a few scans of a CARMEN log. Each program must refuse a value (exit 2, naming key and file)
// or run to its end.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "annotator_node.hpp"
#include "backend_node.hpp"
#include "carmen_config.hpp"
#include "cloud_eval.hpp"
#include "config_walker.hpp"
#include "densifier.hpp"
#include "evaluator.hpp"
#include "frontend_config.hpp"
#include "mapper.hpp"
#include "monitor_node.hpp"
#include "simulator.hpp"
#include "spa.hpp"
#include "viewer_config.hpp"

namespace traverse::test {
namespace {

const std::string kSample = "logs/office-s2_seed1_20s-22s_profile-every-5th.lcmlog";
const std::string kCarmen = "../shared/data/carmen/intel-corrected.log.gz";

std::string bin(const std::string& program) {
  return std::string(TRAVERSE_BIN_DIR) + "/" + program;
}

// The inputs every walk runs on, made once: the sample log through the graph's stages offline
// (each stage's record is the next one's input), a CARMEN excerpt, a small pose graph.
class ConfigWalk : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::filesystem::temp_directory_path() /
           ("traverse-config-walk-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    const auto stage = [](const std::string& program, const std::string& config,
                          const std::string& in, const std::string& out, const std::string& extra) {
      const std::string cmd = bin(program) + " --config " + config + " --replay " + in +
                              " --record " + out + " " + extra + " >/dev/null 2>&1";
      ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    };
    stage("traverse-frontend", "configs/frontend.yaml", kSample, path("frontend.lcmlog"), "");
    stage("traverse-backend", "configs/backend.yaml", path("frontend.lcmlog"),
          path("backend.lcmlog"), "");
    stage("traverse-densifier", "configs/densifier.yaml", path("backend.lcmlog"),
          path("densifier.lcmlog"), "");
    stage("traverse-mapper", "configs/mapper.yaml", path("densifier.lcmlog"), path("mapper.lcmlog"),
          "--out " + path("mapper"));
    // Ten scans of a log subsampled by travel: the frontend's sparse path (the wide search, the
    // ensemble, from the seventh scan the lag).
    if (std::filesystem::exists(kCarmen)) {
      const std::string cut = "zcat " + kCarmen + " | grep -m 10 '^FLASER' > " + path("intel.log");
      ASSERT_EQ(std::system(cut.c_str()), 0);
      const std::string convert = bin("traverse-carmen") + " " + path("intel.log") + " --out " +
                                  path("intel.lcmlog") + " >/dev/null 2>&1";
      ASSERT_EQ(std::system(convert.c_str()), 0) << convert;
    }
    std::ofstream g2o(path("square.g2o"));
    g2o << "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 1.57\nVERTEX_SE2 2 1 1 3.14\n"
           "VERTEX_SE2 3 0 1 -1.57\n";
    const char* info = " 100 0 0 100 0 1000\n";
    g2o << "EDGE_SE2 0 1 1 0 1.5708" << info << "EDGE_SE2 1 2 1 0 1.5708" << info
        << "EDGE_SE2 2 3 1 0 1.5708" << info << "EDGE_SE2 3 0 1 0 1.5708" << info;
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }
  static std::string path(const std::string& name) { return (dir_ / name).string(); }
  static WalkCase walk(const std::string& program, const std::string& config,
                       std::vector<std::string> inputs) {
    WalkCase c;
    c.program = program;
    c.shipped_config = config;
    c.inputs = std::move(inputs);
    c.work_dir = dir_.string();
    return c;
  }
  static bool has_carmen() { return std::filesystem::exists(path("intel.lcmlog")); }

  static std::filesystem::path dir_;
};
std::filesystem::path ConfigWalk::dir_;

TEST_F(ConfigWalk, Frontend) {
  std::vector<std::string> inputs{"--replay " + kSample};
  if (has_carmen()) inputs.push_back("--replay " + path("intel.lcmlog"));
  WalkCase c = walk("traverse-frontend", "configs/frontend.yaml", inputs);
  // Each group of keys on the smallest input that exercises it (a walk of every key on both
  // inputs took 328 s under load): the ICP frontend's with kind icp, on the sample; the
  // handover's on the sample with a swap to ICP halfway and a fresh state directory (the window
  // re-tracked, periodic saves); the sparse path's on the CARMEN scans only.
  c.parts.push_back({{"icp."}, {"--replay " + kSample}, {{"kind", "icp"}}});
  const std::string swap = path("swap.lcmlog");
  const std::string make_swap =
      "python3 scripts/frontend_swap.py insert " + kSample + " " + swap + " 0.5 icp >/dev/null";
  ASSERT_EQ(std::system(make_swap.c_str()), 0) << make_swap;
  c.parts.push_back({{"handover."},
                     {"--replay " + swap + " --state-dir $(mktemp -d " + path("state.XXXXXX)")},
                     {}});
  if (has_carmen()) {
    c.parts.push_back({{"matcher.sparse_", "matcher.wide_search_"}, {inputs[1]}, {}});
  }
  walk_config<frontend::FrontendConfig>(c);
}

TEST_F(ConfigWalk, Backend) {
  walk_config<backend::BackendNodeConfig>(
      walk("traverse-backend", "configs/backend.yaml", {"--replay " + path("frontend.lcmlog")}));
}

TEST_F(ConfigWalk, Annotator) {
  walk_config<annotator::AnnotatorNodeConfig>(
      walk("traverse-annotator", "configs/annotator.yaml", {"--replay " + path("backend.lcmlog")}));
}

TEST_F(ConfigWalk, Densifier) {
  walk_config<densifier::DensifierConfig>(
      walk("traverse-densifier", "configs/densifier.yaml", {"--replay " + path("backend.lcmlog")}));
}

TEST_F(ConfigWalk, Mapper) {
  walk_config<mapper::MapperConfig>(
      walk("traverse-mapper", "configs/mapper.yaml",
           {"--replay " + path("densifier.lcmlog") + " --out " + path("mapper-walk")}));
}

TEST_F(ConfigWalk, Evaluator) {
  walk_config<evaluator::EvaluatorConfig>(
      walk("traverse-evaluator", "configs/evaluator.yaml",
           {"--log " + path("frontend.lcmlog") +
            " --estimate POSE_FRONTEND --reference POSE_GROUND_TRUTH --out " + path("evaluator")}));
}

TEST_F(ConfigWalk, Carmen) {
  if (!has_carmen()) GTEST_SKIP() << "no CARMEN log at " << kCarmen;
  walk_config<carmen::CarmenConfig>(walk("traverse-carmen", "configs/carmen.yaml",
                                         {path("intel.log") + " --out " + path("walk.lcmlog")}));
}

TEST_F(ConfigWalk, Pgo) {
  walk_config<backend::SpaConfig>(walk("traverse-pgo", "configs/pgo.yaml",
                                       {path("square.g2o") + " --out " + path("square-out.g2o")}));
}

TEST_F(ConfigWalk, CloudEval) {
  walk_config<mapper::CloudEvalConfig>(
      walk("traverse-cloud-eval", "configs/cloud-eval-office.yaml",
           {"--world configs/worlds/office.yaml --cloud " + path("mapper/cloud.ply")}));
}

TEST_F(ConfigWalk, Sim) {
  // Half a second of the office route: every sensor has published by then.
  walk_config<sim::SimConfig>(walk("traverse-sim", "configs/sim.yaml",
                                   {"--world configs/worlds/office.yaml --route "
                                    "configs/routes/office-s1.yaml --duration 0.5 --out " +
                                    path("sim.lcmlog")}));
}

TEST_F(ConfigWalk, Monitor) {
  // The monitor listens until stopped: SIGINT after half a second ends a run normally.
  WalkCase c = walk("traverse-monitor", "configs/monitor.yaml", {"--lcm-url memq://"});
  c.stop_after_s = 0.5;
  walk_config<MonitorConfig>(c);
}

TEST_F(ConfigWalk, Viewer) {
  // The viewer serves until stopped (on a free port here): SIGINT after half a second.
  WalkCase c = walk("traverse-viewer", "configs/viewer.yaml", {"--lcm-url memq:// --port 0"});
  c.stop_after_s = 0.5;
  walk_config<viewer::ViewerConfig>(c);
}

}  // namespace
}  // namespace traverse::test
