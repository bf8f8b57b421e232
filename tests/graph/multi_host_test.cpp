// The graph on three machines, each a network namespace made by the test and joined to the others
// by veth pairs on one bridge (a LAN; multicast routed to each host's link, LCM with ttl=1): the
// replay standing in for the drivers (and the recording) on "cart", frontend and backend on
// "server", densifier and mapper on "mapping". The products must match a run on one host.
// Skipped, saying why, where network namespaces cannot be made (not root, no ip netns).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>

#include "deployment.hpp"
#include "graph_test_util.hpp"
#include "json.hpp"
#include "lcm_log.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::graph_test {
namespace {

const std::string kLog = "logs/office-s2_seed1_20s-22s_profile-every-5th.lcmlog";

// Three hosts and a switch as network namespaces, named after this test process so that tests
// running at the same time never share one; removed when the object ends, also on failure.
class Lan {
 public:
  Lan() {
    std::random_device rd;
    prefix_ = "trvmh-" + std::to_string(getpid()) + "-" + std::to_string(rd() % 100000);
  }
  ~Lan() { run(teardown(), 30); }
  std::string ns(const std::string& host) const { return prefix_ + "-" + host; }

  // "" when the namespaces could not be made at all (the skip reason otherwise).
  std::string skip_reason() {
    if (geteuid() != 0) return "not root: cannot create network namespaces";
    // Namespaces left by a test that was killed (its pid is gone) are removed first.
    run("for n in $(ip netns list 2>/dev/null | awk '{print $1}' | grep '^trvmh-'); do "
        "p=${n#trvmh-}; p=${p%%-*}; kill -0 $p 2>/dev/null || ip netns del $n; done",
        30);
    const auto probe = run("ip netns add " + ns("probe") + " && ip netns del " + ns("probe"), 30);
    if (probe.exit_code != 0) return "no network namespaces here (ip netns add): " + probe.output;
    return "";
  }

  // Hosts cart, server, mapping on a bridge in the switch namespace, 10.201.0.0/24.
  CommandResult build() {
    std::string s = "set -e; ";
    for (const char* h : {"sw", "cart", "server", "mapping"}) {
      s += "ip netns add " + ns(h) + "; ip -n " + ns(h) + " link set lo up; ";
    }
    s += "ip -n " + ns("sw") + " link add br0 type bridge mcast_snooping 0; ";
    int i = 1;
    for (const char* h : {"cart", "server", "mapping"}) {
      const std::string host = ns(h), sw = ns("sw"), port = std::string("p-") + h;
      s += "ip -n " + sw + " link add " + port + " type veth peer name eth0 netns " + host + "; ";
      s += "ip -n " + sw + " link set " + port + " master br0 up; ";
      s += "ip -n " + host + " addr add 10.201.0." + std::to_string(i++) + "/24 dev eth0; ";
      s += "ip -n " + host + " link set eth0 up; ";
      s += "ip -n " + host + " route add 224.0.0.0/4 dev eth0; ";
    }
    s += "ip -n " + ns("sw") + " link set br0 up";
    return run(s, 30);
  }

 private:
  std::string teardown() const {
    std::string s;
    for (const char* h : {"sw", "cart", "server", "mapping"}) {
      s += "ip netns del " + ns(h) + " 2>/dev/null; ";
    }
    return s + "true";
  }
  std::string prefix_;
};

// The graph with an evaluator of the dense trajectory against the simulator's ground truth: on
// three hosts of `lan` with `ttl`, or (no lan) on this one.
std::string deployment(const Lan* lan, const std::string& ttl = "1") {
  std::string d;
  const auto on = [&](const std::string& host) { return lan ? ", host: " + host : std::string(); };
  if (lan) {
    d = "lcm_url: \"udpm://239.255.76.67:7667?ttl=" + ttl + "&recv_buf_size=8388608\"\nhosts:\n";
    for (const char* h : {"cart", "server", "mapping"}) {
      d += "  - {name: " + std::string(h) + ", netns: " + lan->ns(h) + "}\n";
    }
  }
  return d + "processes:\n" +
         "  - {name: frontend, program: traverse-frontend, config: configs/frontend.yaml" +
         on("server") + "}\n" +
         "  - {name: backend, program: traverse-backend, config: configs/backend.yaml" +
         on("server") + "}\n" +
         "  - {name: densifier, program: traverse-densifier, config: configs/densifier.yaml" +
         on("mapping") + "}\n" +
         "  - {name: mapper, program: traverse-mapper, config: configs/mapper.yaml, " +
         "args: [--out, \"{out}/mapper\"], stop_timeout_s: 600" + on("mapping") + "}\n" +
         "  - {name: evaluator, program: traverse-evaluator, config: configs/evaluator.yaml, " +
         "args: [--estimate, DENSE_SEGMENTS, --out, \"{out}/evaluator\"]" + on("mapping") + "}\n";
}

std::string run_graph(const std::string& deploy, const std::filesystem::path& out,
                      const std::string& extra = "") {
  return "TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/run-graph.sh --deploy " + deploy + " --log " +
         kLog + " --out " + out.string() + " --grace 1 " + extra;
}

// What a run produced: frontend poses, the backend's final key poses, the mapper's cloud.
struct Products {
  int64_t frontend_poses = 0;
  pose2d_t last_frontend;
  std::map<int64_t, key_pose_t> key_poses;  // newest version of each key pose
  int64_t cloud_points = -1;
  double dense_rmse_m = -1.0;  // the evaluator's position RMSE of the dense trajectory
};

Products products(const std::filesystem::path& out) {
  Products p;
  LogReader reader((out / "run.lcmlog").string());
  while (auto ev = reader.next()) {
    const int size = static_cast<int>(ev->data.size());
    if (ev->channel == "POSE_FRONTEND" && p.last_frontend.decode(ev->data.data(), 0, size) > 0) {
      ++p.frontend_poses;
    }
    key_poses_t k;
    if (ev->channel == "KEY_POSES" && k.decode(ev->data.data(), 0, size) > 0) {
      for (const auto& kp : k.poses) p.key_poses[kp.id] = kp;
    }
  }
  std::ifstream log(out / "evaluator.log");
  for (std::string line; std::getline(log, line);) {
    if (line.empty() || line.front() != '{') continue;  // the evaluator's JSON line
    const Json j = Json::parse(line, nullptr, false);
    if (!j.is_discarded() && j.contains("position_rmse_m") && j["position_rmse_m"].is_number()) {
      p.dense_rmse_m = j["position_rmse_m"].get<double>();
    }
  }
  std::ifstream ply(out / "mapper" / "cloud.ply");
  for (std::string line; std::getline(ply, line) && line != "end_header";) {
    if (line.rfind("element vertex ", 0) == 0) p.cloud_points = std::stoll(line.substr(15));
  }
  return p;
}

TEST(MultiHost, ThreeNamespacesGiveTheProductsOfOneHost) {
  Lan lan;
  if (const std::string why = lan.skip_reason(); !why.empty()) GTEST_SKIP() << why;
  const auto made = lan.build();
  ASSERT_EQ(made.exit_code, 0) << "building the namespaces failed:\n" << made.output;
  const auto dir = temp_dir("multi-host");

  const std::string single = (dir / "one.yaml").string(), deploy = (dir / "lan.yaml").string();
  std::ofstream(single) << deployment(nullptr);
  const auto one = run(run_graph(single, dir / "one"), 120);
  ASSERT_EQ(one.exit_code, 0) << one.output;
  std::ofstream(deploy) << deployment(&lan, "1");
  const auto three = run(run_graph(deploy, dir / "three"), 120);
  ASSERT_EQ(three.exit_code, 0) << three.output;

  // Each process reported the host the deployment put it on, and the recording on "cart" heard
  // every one of them across the bridge.
  const std::map<std::string, std::string> where = {
      {"STATUS_FRONTEND", "server"},   {"STATUS_BACKEND", "server"},
      {"STATUS_DENSIFIER", "mapping"}, {"STATUS_MAPPER", "mapping"},
      {"STATUS_EVALUATOR", "mapping"}, {"STATUS_MONITOR", "cart"}};
  std::map<std::string, int> heard;
  for (const auto& s : statuses((dir / "three" / "run.lcmlog").string())) {
    if (!where.count(s.channel)) continue;
    ++heard[s.channel];
    EXPECT_EQ(s.host, where.at(s.channel)) << s.channel;
    for (const auto& [channel, missed] : s.missed) {
      EXPECT_EQ(missed, 0) << s.channel << " missed messages on " << channel;
    }
  }
  for (const auto& [channel, host] : where) EXPECT_GT(heard[channel], 0) << channel;

  // The same products within tolerance: every scan through the frontend, the same key poses
  // within 1 mm and 1 mrad, the cloud's size within 1 %.
  const Products a = products(dir / "one"), b = products(dir / "three");
  EXPECT_GT(a.frontend_poses, 90);
  EXPECT_EQ(b.frontend_poses, a.frontend_poses);
  EXPECT_NEAR(b.last_frontend.x, a.last_frontend.x, 1e-3);
  EXPECT_NEAR(b.last_frontend.y, a.last_frontend.y, 1e-3);
  ASSERT_GT(a.key_poses.size(), 1u);
  ASSERT_EQ(b.key_poses.size(), a.key_poses.size());
  double worst_m = 0.0;
  for (const auto& [id, ka] : a.key_poses) {
    const key_pose_t& kb = b.key_poses.at(id);
    worst_m = std::max(worst_m, std::hypot(kb.x - ka.x, kb.y - ka.y));
    EXPECT_NEAR(std::hypot(kb.x - ka.x, kb.y - ka.y), 0.0, 1e-3) << "key pose " << id;
    EXPECT_NEAR(kb.theta, ka.theta, 1e-3) << "key pose " << id;
  }
  std::printf(
      "one host / three hosts: %lld / %lld frontend poses, %zu / %zu key poses (largest "
      "difference %.6f m), %lld / %lld cloud points, dense RMSE %.6f / %.6f m\n",
      static_cast<long long>(a.frontend_poses), static_cast<long long>(b.frontend_poses),
      a.key_poses.size(), b.key_poses.size(), worst_m, static_cast<long long>(a.cloud_points),
      static_cast<long long>(b.cloud_points), a.dense_rmse_m, b.dense_rmse_m);
  ASSERT_GT(a.dense_rmse_m, 0.0);
  EXPECT_NEAR(b.dense_rmse_m, a.dense_rmse_m, 1e-3);
  ASSERT_GT(a.cloud_points, 1000);
  EXPECT_NEAR(static_cast<double>(b.cloud_points), static_cast<double>(a.cloud_points),
              0.01 * static_cast<double>(a.cloud_points));

  // With ttl=0 nothing leaves "cart": the processes on the other hosts are never heard, so the
  // namespaces are really separate machines.
  std::ofstream(deploy) << deployment(&lan, "0");
  const auto alone = run(run_graph(deploy, dir / "ttl0", "--ready-timeout 2"), 120);
  EXPECT_NE(alone.output.find("no status from 'frontend'"), std::string::npos) << alone.output;
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

// As in the field: one launcher per host with the same deployment file, here both on this
// machine. The server's launcher (no log) starts only the frontend and runs until stopped; the
// cart's replays, records and judges, and hears the frontend on "server".
TEST(MultiHost, OneLauncherPerHostEachStartsItsOwnProcesses) {
  const auto dir = temp_dir("field");
  const auto lease = launch::reserve_port((dir / "ports").string(), 30000, 39999);
  ASSERT_TRUE(lease);
  const std::string url = launch::private_url(lease->port(), 8 << 20);
  const std::string deploy = (dir / "field.yaml").string();
  std::ofstream(deploy) << "hosts: [{name: cart}, {name: server}]\n"
                           "processes:\n"
                           "  - {name: frontend, program: traverse-frontend, "
                           "config: configs/frontend.yaml, host: server}\n";
  const std::string bin = "TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/run-graph.sh --deploy " +
                          deploy + " --lcm-url \"" + url + "\" ";
  // As an operator would: once the replay is over, the server is stopped first (its frontend's
  // last pose goes out as it stops), while the cart still records (--grace).
  const std::string cart_status = (dir / "cart" / "processes.json").string();
  const auto r = run(
      bin + "--host server --out " + (dir / "server").string() + " > " +
          (dir / "server.out").string() + " 2>&1 & server=$!; sleep 1; " + bin +
          "--host cart --log " + kLog + " --out " + (dir / "cart").string() +
          " --grace 4 & cart=$!; sleep 2; until [ \"$(python3 scripts/conf.py get " + cart_status +
          " processes.logplayer.running 2>/dev/null)\" = false ] || ! kill -0 $cart; do sleep 0.2;"
          " done; kill -INT $server; wait $server; server=$?; " +
          "wait $cart; echo cart=$? server=$server; cat " + (dir / "server.out").string(),
      120);
  EXPECT_NE(r.output.find("cart=0 server=130"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("not started here: frontend (server)"), std::string::npos) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "server" / "frontend.log"));
  EXPECT_FALSE(std::filesystem::exists(dir / "server" / "run.lcmlog"));  // no recording there
  const auto counts = count_channels((dir / "cart" / "run.lcmlog").string());
  EXPECT_EQ(counts.count("POSE_FRONTEND") ? counts.at("POSE_FRONTEND") : 0, 96);
  bool heard_server = false;
  for (const auto& s : statuses((dir / "cart" / "run.lcmlog").string())) {
    heard_server = heard_server || (s.channel == "STATUS_FRONTEND" && s.host == "server");
  }
  EXPECT_TRUE(heard_server);
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::graph_test
