#include "graph_test_util.hpp"

#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "lcm_log.hpp"
#include "traverse/process_status_t.hpp"

namespace traverse::graph_test {

CommandResult run(const std::string& command, int timeout_s) {
  CommandResult r;
  const std::string full =
      "timeout -k 5 " + std::to_string(timeout_s) + " sh -c '" + command + "' 2>&1";
  FILE* pipe = popen(full.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), pipe))
    r.output.append(buf.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

std::string bin_dir() { return TRAVERSE_BIN_DIR; }

double json_number(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\": ");
  EXPECT_NE(at, std::string::npos) << key << " in " << json;
  return at == std::string::npos ? -1.0 : std::stod(json.substr(at + key.size() + 4));
}

std::string route_json(const std::string& output) {
  const auto at = output.rfind("{\"route\"");
  EXPECT_NE(at, std::string::npos) << "no JSON line in " << output;
  return at == std::string::npos ? std::string() : output.substr(at);
}

std::string eval_route(const std::string& args) {
  const auto r = run("TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/eval-route.sh " + args, 600);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return route_json(r.output);
}

std::string read_text(const std::filesystem::path& path) {
  std::stringstream s;
  s << std::ifstream(path).rdbuf();
  return s.str();
}

int running_pid(const std::filesystem::path& processes_json, const std::string& name) {
  const std::regex entry("\\{\"name\":\"" + name + "\",\"host\":\"[^\"]*\",\"pid\":([0-9]+)," +
                         "\"running\":true");
  std::smatch m;
  const std::string text = read_text(processes_json);
  return std::regex_search(text, m, entry) ? std::stoi(m[1]) : 0;
}

std::vector<std::string> traverse_programs() {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(bin_dir())) {
    const std::string file = e.path().filename().string();
    if (file.rfind("traverse-", 0) == 0 && access(e.path().c_str(), X_OK) == 0) {
      names.push_back(file.substr(9));
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::filesystem::path temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("traverse-graph-test-" + std::to_string(getpid()) + "-" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::map<std::string, int64_t> count_channels(const std::string& lcm_log) {
  std::map<std::string, int64_t> counts;
  LogReader reader(lcm_log);
  while (auto ev = reader.next()) ++counts[ev->channel];
  EXPECT_TRUE(reader.damage().empty()) << lcm_log << " is damaged";
  return counts;
}

std::vector<StatusMessage> statuses(const std::string& lcm_log) {
  std::vector<StatusMessage> out;
  LogReader reader(lcm_log);
  while (auto ev = reader.next()) {
    if (ev->channel.rfind("STATUS_", 0) != 0) continue;
    process_status_t st;
    if (st.decode(ev->data.data(), 0, static_cast<int>(ev->data.size())) < 0) continue;
    StatusMessage m{ev->channel, st.utime, st.pid, st.host, {}};
    for (const auto& c : st.channels) m.missed[c.channel] = c.missed;
    out.push_back(std::move(m));
  }
  return out;
}

std::string short_intel_log(const std::filesystem::path& dir, int lines) {
  const std::string text = (dir / "intel-head.log").string();
  const std::string lcm_log = (dir / "intel-head.lcmlog").string();
  const auto r =
      run("zcat ../shared/data/carmen/intel-corrected.log.gz | head -" + std::to_string(lines) +
              " > " + text + " && " + bin_dir() + "/traverse-carmen " + text + " --out " + lcm_log,
          60);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return lcm_log;
}

double position_rmse(const std::filesystem::path& run_dir, const std::string& channel) {
  const auto r = run(bin_dir() + "/traverse-evaluator --config configs/evaluator.yaml --log " +
                         (run_dir / "run.lcmlog").string() + " --estimate " + channel +
                         " --reference POSE_GROUND_TRUTH --out " + run_dir.string() +
                         " | tail -1 | python3 scripts/conf.py get - position_rmse_m",
                     60);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return r.exit_code == 0 ? std::stod(r.output) : -1.0;
}

int kill_into_replay(const std::filesystem::path& processes_json, const std::string& victim,
                     double delay_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline && !running_pid(processes_json, "logplayer")) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::this_thread::sleep_for(std::chrono::duration<double>(delay_s));
  const int pid = running_pid(processes_json, victim);
  if (pid > 0) kill(pid, SIGKILL);
  return pid;
}

int64_t cloud_points(const std::filesystem::path& ply) {
  std::ifstream in(ply);
  std::string line;
  while (std::getline(in, line) && line != "end_header") {
    if (line.rfind("element vertex ", 0) == 0) return std::stoll(line.substr(15));
  }
  return -1;
}

std::set<std::tuple<int, int, int>> occupied_voxels(const std::filesystem::path& bt) {
  std::set<std::tuple<int, int, int>> out;
  octomap::OcTree tree(0.1);  // the file's resolution replaces this
  if (!tree.readBinary(bt.string())) return out;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    if (tree.isNodeOccupied(*it)) out.emplace(it.getKey()[0], it.getKey()[1], it.getKey()[2]);
  }
  return out;
}

std::vector<pose2d_t> poses_on(const std::string& lcm_log, const std::string& channel) {
  std::vector<pose2d_t> out;
  LogReader reader(lcm_log);
  while (auto ev = reader.next()) {
    pose2d_t p;
    if (ev->channel == channel &&
        p.decode(ev->data.data(), 0, static_cast<int>(ev->data.size())) > 0)
      out.push_back(p);
  }
  return out;
}

}  // namespace traverse::graph_test
