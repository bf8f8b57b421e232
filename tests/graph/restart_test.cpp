// The deployment's policy for a process that dies: a densifier killed with SIGKILL mid-run is
// restarted and the run goes on (the launcher's report, processes.json, the monitor and the
// recorded statuses all say so); a process that keeps dying is given up after max_restarts; one
// under stop_graph stops the whole graph at once.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <fstream>
#include <set>
#include <thread>

#include "graph_test_util.hpp"

namespace traverse::graph_test {
namespace {

const std::string kLog = "logs/office-s2_seed1_20s-22s_profile-every-5th.lcmlog";

std::string launch(const std::string& deploy, const std::filesystem::path& out,
                   const std::string& extra) {
  return "TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/run-graph.sh --deploy " + deploy + " --log " +
         kLog + " --out " + out.string() + " --grace 1 " + extra;
}

TEST(Restart, ADensifierKilledMidRunIsRestartedAndReported) {
  const auto dir = temp_dir("restart");
  const std::string deploy = (dir / "deploy.yaml").string();
  std::ofstream(deploy)
      << "processes:\n"
         "  - {name: frontend, program: traverse-frontend, config: configs/frontend.yaml}\n"
         "  - {name: backend, program: traverse-backend, config: configs/backend.yaml}\n"
         "  - {name: densifier, program: traverse-densifier, config: configs/densifier.yaml,\n"
         "     on_death: restart, max_restarts: 2, restart_delay_s: 0.2}\n";
  // The 2 s log at a quarter of its pace: 8 s of replay; SIGKILL once the replay is under way.
  const std::string out = (dir / "run").string();
  std::thread killer([&] {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < deadline &&
           !running_pid(dir / "run" / "processes.json", "logplayer")) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    std::this_thread::sleep_for(std::chrono::seconds(3));
    const int pid = running_pid(dir / "run" / "processes.json", "densifier");
    if (pid > 0) kill(pid, SIGKILL);
    std::ofstream(dir / "killed") << pid;
  });
  const auto r = run(launch(deploy, dir / "run", "--speed 0.25"), 120);
  killer.join();
  int killed = 0;
  std::ifstream(dir / "killed") >> killed;
  ASSERT_GT(killed, 0) << "no densifier pid in processes.json\n" << r.output;

  // The densifier came back and lasted to the end: the run is ok, and the report says why.
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("densifier died (killed by SIGKILL (died)); restart 1 of 2"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("\"name\":\"densifier\",\"host\":\"\",\"program\":\"traverse-"
                          "densifier\",\"restarts\":1"),
            std::string::npos)
      << r.output;
  EXPECT_NE(read_text(dir / "run" / "processes.json").find("\"restarts\":1"), std::string::npos);
  // Its statuses in the recording come from two pids, the killed one first; the monitor counted
  // one restart.
  std::vector<int32_t> pids;
  for (const auto& s : statuses(out + "/run.lcmlog")) {
    if (s.channel == "STATUS_DENSIFIER" && (pids.empty() || pids.back() != s.pid)) {
      pids.push_back(s.pid);
    }
  }
  ASSERT_EQ(pids.size(), 2u) << r.output;
  EXPECT_EQ(pids[0], killed);
  EXPECT_NE(read_text(dir / "run" / "monitor.json").find("\"restarts\":1"), std::string::npos)
      << read_text(dir / "run" / "monitor.json");
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

TEST(Restart, GivesUpAfterMaxRestartsOrStopsTheGraph) {
  const auto dir = temp_dir("give-up");
  for (const std::string policy :
       {"restart, max_restarts: 2, restart_delay_s: 0.1", "stop_graph"}) {
    const std::string deploy = (dir / "deploy.yaml").string();
    std::ofstream(deploy) << "processes:\n"
                             "  - {name: doomed, program: traverse-carmen,\n"
                             "     args: [/nonexistent/carmen.log], on_death: " +
                                 policy + "}\n";
    // At 0.25x the replay would take 8 s.
    const auto started = std::chrono::steady_clock::now();
    const auto r = run(launch(deploy, dir / "run", "--speed 0.25"), 60);
    const double took_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("\"failed\":[\"doomed\"]"), std::string::npos) << r.output;
    if (policy == "stop_graph") {
      EXPECT_NE(r.output.find("\"stopped_by\":\"doomed\""), std::string::npos) << r.output;
      EXPECT_LT(took_s, 7.0) << "the graph was not stopped at once\n" << r.output;
    } else {
      EXPECT_NE(r.output.find("restart 2 of 2"), std::string::npos) << r.output;
      EXPECT_NE(r.output.find("given up after 2 restart(s)"), std::string::npos) << r.output;
      EXPECT_EQ(r.output.find("restart 3"), std::string::npos) << r.output;
      EXPECT_NE(r.output.find("\"stopped_by\":\"\""), std::string::npos) << r.output;
    }
  }
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

// Per-process commands to a running launcher: stop the frontend, see it stopped in the status,
// start it again, see it running under a new pid; the run's report lists both commands.
TEST(Restart, ControlStopsAndStartsOneProcessOfARunningGraph) {
  const auto dir = temp_dir("control");
  const std::string deploy = (dir / "deploy.yaml").string();
  std::ofstream(deploy) << "processes:\n"
                           "  - {name: frontend, program: traverse-frontend, "
                           "config: configs/frontend.yaml}\n";
  const std::string control = "TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/run-graph.sh --out " +
                              (dir / "run").string() + " --control ";
  const auto status = dir / "run" / "processes.json";
  std::string stopped, started, listed;
  std::thread operator_thread([&] {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < deadline && !running_pid(status, "logplayer")) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    stopped = run(control + "stop --process frontend", 60).output;
    started = run(control + "start --process frontend", 60).output;
    listed = run(control + "status", 60).output;
  });
  const auto r = run(launch(deploy, dir / "run", "--speed 0.25"), 120);
  operator_thread.join();
  EXPECT_NE(stopped.find("{\"name\":\"frontend\",\"host\":\"\",\"pid\":"), std::string::npos)
      << stopped;
  EXPECT_NE(stopped.find("\"running\":false,\"restarts\":0,\"outcome\":\"exit 0 after SIGINT\""),
            std::string::npos)
      << stopped;
  EXPECT_NE(started.find("\"running\":true,\"restarts\":1"), std::string::npos) << started;
  EXPECT_NE(listed.find("\"name\":\"logger\""), std::string::npos) << listed;
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("stop frontend: exit 0 after SIGINT"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("start frontend: running (pid "), std::string::npos) << r.output;
  // Nobody listens any more: a command is refused, not lost silently.
  EXPECT_EQ(run(control + "stop --process frontend", 60).exit_code, 1);
  EXPECT_EQ(run(control + "halt --process frontend", 60).exit_code, 2);
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::graph_test
