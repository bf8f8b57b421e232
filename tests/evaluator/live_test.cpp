// The evaluator as a listening process: poses published on a private LCM URL, outputs at SIGINT.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

#include "bus.hpp"
#include "json.hpp"
#include "messages.hpp"
#include "synthetic.hpp"
#include "traverse/pose2d_t.hpp"
#include "traverse/process_status_t.hpp"

namespace traverse::evaluator {
namespace {

// A port of its own so that no other test's traffic is heard.
constexpr const char* kUrl = "udpm://239.255.76.67:7934?ttl=0";

// Waits (up to a generous timeout, never a fixed delay) for a status of the evaluator whose
// counter `name` has reached `value`; any value when `name` is empty.
bool wait_for_status(const std::string& name, double value) {
  Bus bus(kUrl);
  bool seen = false;
  bus.subscribe<process_status_t>(
      "STATUS_EVALUATOR",
      [&](const process_status_t& st) {
        if (name.empty()) seen = true;
        for (int i = 0; i < st.n_counters; ++i) {
          if (st.counter_names[i] == name && st.counter_values[i] >= value) seen = true;
        }
      },
      true);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!seen && std::chrono::steady_clock::now() < deadline) bus.handle(100);
  return seen;
}

// Kills the program if the test ends early, so that no listener outlives it.
struct ChildGuard {
  pid_t pid = -1;
  ~ChildGuard() {
    if (pid > 0) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  }
};

TEST(EvaluatorLive, WritesItsSummaryWhenStopped) {
  int out_pipe[2];
  ASSERT_EQ(pipe(out_pipe), 0);
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    dup2(out_pipe[1], STDOUT_FILENO);
    close(out_pipe[0]);
    const std::string bin = std::string(TRAVERSE_BIN_DIR) + "/traverse-evaluator";
    execl(bin.c_str(), bin.c_str(), "--lcm-url", kUrl, "--align", "none", nullptr);
    _exit(127);
  }
  close(out_pipe[1]);
  ChildGuard guard{pid};

  {
    ASSERT_TRUE(wait_for_status("", 0)) << "evaluator never reported";
    Bus bus(kUrl);
    ASSERT_TRUE(bus.good());
    // 2 s of ground truth at 200 Hz, a frontend at 40 Hz 0.1 m off in y. Sent in chunks of
    // 0.5 s (120 messages, about 120 kB of socket buffer) and each chunk waited for in the
    // evaluator's status before the next, so that no burst outgrows the receiver's socket buffer
    // at its default size, whatever the machine's load (sent with short pauses instead, 9 truth
    // poses were lost once in CI).
    int frontend = 0;
    int truth = 0;
    for (const StampedPose& p : test::circle_truth(2)) {
      pose2d_t msg = test::pose_message(p);
      bus.publish("POSE_GROUND_TRUTH", msg);
      ++truth;
      if ((p.utime / 5'000) % 5 == 0) {
        msg.y += 0.1;
        bus.publish("POSE_FRONTEND", msg);
        ++frontend;
      }
      if (truth % 100 == 0) {
        ASSERT_TRUE(wait_for_status("reference_poses", truth)) << truth;
      }
    }
    EXPECT_TRUE(wait_for_status("reference_poses", truth));
    EXPECT_TRUE(wait_for_status("estimate_poses", frontend));
  }
  kill(pid, SIGINT);

  std::string output;
  char buf[4096];
  ssize_t n;
  while ((n = read(out_pipe[0], buf, sizeof(buf))) > 0) output.append(buf, static_cast<size_t>(n));
  close(out_pipe[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  guard.pid = -1;
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << output;
  // The summary is the last line of the output, one JSON object.
  const std::size_t end = output.find_last_not_of('\n');
  ASSERT_NE(end, std::string::npos) << output;
  const std::size_t start = output.rfind('\n', end);
  const traverse::Json summary =
      traverse::Json::parse(output.substr(start == std::string::npos ? 0 : start + 1,
                                          end + 1 - (start == std::string::npos ? 0 : start + 1)));
  EXPECT_NEAR(summary.at("position_rmse_m").get<double>(), 0.1, 1e-6) << output;
  EXPECT_EQ(summary.at("matched").get<int>(), 81) << output;
}

}  // namespace
}  // namespace traverse::evaluator
