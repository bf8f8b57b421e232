// The launcher's pieces without starting a graph: deployment files, stage selection, private
// ports, and the supervisor's escalation from SIGINT to SIGKILL.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <fstream>
#include <thread>

#include "config.hpp"
#include "deployment.hpp"
#include "graph_test_util.hpp"
#include "supervisor.hpp"

namespace traverse::launch {
namespace {

std::string write(const std::filesystem::path& dir, const std::string& name,
                  const std::string& text) {
  const auto path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

// Each deployment text is refused with an error naming its needle.
void expect_refused(const std::filesystem::path& dir,
                    const std::vector<std::pair<std::string, std::string>>& cases) {
  for (const auto& [text, needle] : cases) {
    const auto path = write(dir, "bad.yaml", text);
    try {
      load_deployment(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  }
}

TEST(Deployment, LoadsSelectsAndRejects) {
  const auto dir = graph_test::temp_dir("deploy");
  const auto good = write(dir, "good.yaml",
                          "processes:\n"
                          "  - {name: a, program: traverse-a, config: configs/a.yaml}\n"
                          "  - {name: b, program: traverse-b, args: [--x, '1']}\n"
                          "  - {name: c, program: traverse-c}\n");
  const Deployment d = load_deployment(good);
  ASSERT_EQ(d.processes.size(), 3u);
  EXPECT_EQ(d.processes[1].args, (std::vector<std::string>{"--x", "1"}));
  std::string error;
  const auto some = select_stages(d, "c,a", error);
  ASSERT_TRUE(some);
  ASSERT_EQ(some->size(), 2u);
  EXPECT_EQ((*some)[0].name, "a");  // graph order, not list order
  EXPECT_EQ(select_stages(d, "all", error)->size(), 3u);
  EXPECT_FALSE(select_stages(d, "a,zzz", error));
  EXPECT_NE(error.find("zzz"), std::string::npos);

  // An optional stage (the viewer) runs only when named: "all" leaves it out, "all,v" adds it.
  const Deployment with_optional =
      load_deployment(write(dir, "optional.yaml",
                            "processes:\n"
                            "  - {name: a, program: traverse-a}\n"
                            "  - {name: v, program: traverse-v, optional: true}\n"
                            "  - {name: c, program: traverse-c}\n"));
  EXPECT_EQ(select_stages(with_optional, "all", error)->size(), 2u);
  EXPECT_EQ(select_stages(with_optional, "", error)->size(), 2u);
  const auto plus = select_stages(with_optional, "all,v", error);
  ASSERT_TRUE(plus);
  ASSERT_EQ(plus->size(), 3u);
  EXPECT_EQ((*plus)[1].name, "v");
  EXPECT_EQ(select_stages(with_optional, "v", error)->size(), 1u);

  expect_refused(dir,
                 {{"processes:\n  - {name: a, program: p, confg: x}\n", "confg"},
                  {"processes:\n  - {name: a, program: p}\n  - {name: a, program: q}\n", "twice"},
                  {"processes:\n  - {name: monitor, program: p}\n", "reserved"},
                  {"processes:\n  - {program: p}\n", "name"},
                  {"stages: []\n", "stages"}});
  std::filesystem::remove_all(dir);
}

TEST(Deployment, HostsPoliciesAndWhatEachLauncherStarts) {
  const auto dir = graph_test::temp_dir("deploy-hosts");
  const auto path = write(dir, "hosts.yaml",
                          "lcm_url: 'udpm://239.255.76.67:7667?ttl=1'\n"
                          "hosts: [{name: cart}, {name: server}, {name: lab, netns: ns-lab}]\n"
                          "processes:\n"
                          "  - {name: a, program: p}\n"
                          "  - {name: b, program: p, host: server, on_death: restart}\n"
                          "  - {name: c, program: p, host: lab, on_death: stop_graph}\n");
  const Deployment d = load_deployment(path);
  EXPECT_EQ(d.lcm_url, "udpm://239.255.76.67:7667?ttl=1");
  EXPECT_EQ(d.processes[0].host, "cart");  // no host: the first
  EXPECT_EQ(d.processes[0].on_death, "report");
  EXPECT_EQ(d.processes[1].max_restarts, 3);
  const auto names = [](const std::vector<StageSpec>& v) {
    std::string s;
    for (const auto& x : v) s += x.name;
    return s;
  };
  // Its own processes, and those of a host standing in a network namespace.
  EXPECT_EQ(names(started_here(d, d.processes, "cart")), "ac");
  EXPECT_EQ(names(started_here(d, d.processes, "server")), "bc");
  Deployment flat;
  flat.processes = d.processes;
  EXPECT_EQ(names(started_here(flat, flat.processes, "")), "abc");

  const std::string head = "hosts: [{name: cart}]\nprocesses:\n";
  expect_refused(dir, {{head + "  - {name: a, program: p, host: moon}\n", "moon"},
                       {head + "  - {name: a, program: p, on_death: retry}\n", "on_death"},
                       {head + "  - {name: a, program: p, max_restarts: -1}\n", "max_restarts"},
                       {"hosts: [{name: x}, {name: x}]\nprocesses: []\n", "twice"},
                       {"hosts: [{name: x, ip: 1}]\nprocesses: []\n", "ip"},
                       {"lcm_url: tcpq://x\nprocesses: []\n", "lcm_url"}});
  // The committed examples load.
  for (const char* f : {"configs/deploy/pipeline.yaml", "configs/deploy/two-hosts.yaml"}) {
    EXPECT_NO_THROW(load_deployment(f)) << f;
  }
  std::filesystem::remove_all(dir);
}

TEST(PortLease, TwoLeasesNeverShareAPort) {
  const auto dir = graph_test::temp_dir("ports");
  // A range of two ports: two leases take both, a third finds none until one is released.
  auto a = reserve_port(dir.string(), 31450, 31451);
  auto b = reserve_port(dir.string(), 31450, 31451);
  ASSERT_TRUE(a && b);
  EXPECT_NE(a->port(), b->port());
  EXPECT_FALSE(reserve_port(dir.string(), 31450, 31451));
  const int freed = a->port();
  a.reset();
  auto c = reserve_port(dir.string(), 31450, 31451);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->port(), freed);
  EXPECT_EQ(private_url(c->port(), 8 << 20),
            "udpm://239.255.76.67:" + std::to_string(freed) + "?ttl=0&recv_buf_size=8388608");
  EXPECT_EQ(recv_buf_size_of(private_url(1, 123)), 123);
  std::filesystem::remove_all(dir);
}

TEST(Supervisor, EscalatesToSigkillForAProcessThatIgnoresSigint) {
  const auto dir = graph_test::temp_dir("supervisor");
  Supervisor sup;
  std::string error;
  ASSERT_TRUE(sup.spawn("stubborn",
                        {"/bin/sh", "-c", "trap '' INT TERM; while :; do sleep 0.05; done"},
                        (dir / "stubborn.log").string(), error));
  ASSERT_TRUE(sup.spawn("polite", {"/bin/sleep", "30"}, (dir / "polite.log").string(), error));
  ASSERT_TRUE(
      sup.spawn("missing", {"/nonexistent/program"}, (dir / "missing.log").string(), error));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  sup.reap();
  const Child* missing = sup.find("missing");
  EXPECT_FALSE(missing->running);
  EXPECT_EQ(missing->exit_code, 127);
  EXPECT_TRUE(missing->died());
  sup.stop({"stubborn", "polite"}, 0.3);
  EXPECT_EQ(sup.find("polite")->term_signal, SIGINT);
  EXPECT_FALSE(sup.find("polite")->died());
  EXPECT_EQ(sup.find("stubborn")->term_signal, SIGKILL);
  EXPECT_EQ(sup.find("stubborn")->last_signal_sent, "SIGKILL");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::launch
