// What run-graph starts: a deployment file lists the processes of a graph in graph order,
//
//   processes:
//     - name: frontend                  # instance name; status on STATUS_FRONTEND
//       program: traverse-frontend      # looked up in the build's bin/ (or a path with '/')
//       config: configs/frontend.yaml   # optional; relative paths are from the repository root
//       args: [--out, "{out}/frontend"]  # optional extra arguments; {out} = the run's folder
//       stop_timeout_s: 60              # optional: time it may take to stop (e.g. exports)
//       host: server                    # optional: one of `hosts` (default: the first host)
//       on_death: restart               # optional: report (default), restart or stop_graph
//       max_restarts: 3                 # with restart: then give up (it stays down, reported)
//       optional: true                  # started only when --stages names it ("all" leaves it)
//
// and the launcher gives each one its config, --name and the one LCM URL of the run. A graph on
// several machines also says
//
//   lcm_url: "udpm://239.255.76.67:7667?ttl=1&recv_buf_size=8388608"   # ttl=1: the LAN
//   hosts:
//     - name: cart                      # the first host records the run and replays the log
//     - name: server
//       netns: ""                       # optional: a network namespace standing in for it
//
// A launcher started as one host (--host) starts that host's processes and those of every host
// with a network namespace (entering it); each other host runs its own launcher with the same
// file. Also here: choosing a private LCM port that no other run on this machine holds.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace traverse::launch {

struct StageSpec {
  std::string name;
  std::string program;
  std::string config;
  std::vector<std::string> args;
  double stop_timeout_s = 0.0;  // [s] from SIGINT to SIGTERM; 0: the launcher's --stop-timeout
  std::string host;             // where it runs: a name in Deployment::hosts ("": the first)
  // When it dies (ends on its own with a failure): "report" (the run goes on without it and
  // fails at the end), "restart" (at most max_restarts times, then as "report"), or "stop_graph"
  // (the whole graph stops at once and the run fails).
  std::string on_death = "report";
  int max_restarts = 3;
  double restart_delay_s = 0.5;  // [s] from its death to its restart
  // Started only when the stage list names it (e.g. the viewer: "all,viewer"); "all" leaves it out.
  bool optional = false;

  template <class V>
  void visit(V& v) {
    v("name", name);
    v("program", program);
    v("config", config);
    v("args", args);
    v("stop_timeout_s", stop_timeout_s);
    v("host", host);
    v("on_death", on_death);
    v("max_restarts", max_restarts);
    v("restart_delay_s", restart_delay_s);
    v("optional", optional);
  }
};

// One machine of the graph. `netns` (for tests on one machine): the name of a network namespace
// (ip netns) that stands in for it; the launcher starts the host's processes inside it. Without
// one, the host runs its own launcher (--host NAME) with the same deployment file.
struct HostSpec {
  std::string name;
  std::string netns;

  template <class V>
  void visit(V& v) {
    v("name", name);
    v("netns", netns);
  }
};

// The first value out of range, named by its key; nullopt when the stage is usable.
std::optional<std::string> validate(const StageSpec& stage);

struct Deployment {
  // The run's LCM URL; empty: a private port on this host only (ttl=0). --lcm-url overrides it.
  std::string lcm_url;
  std::vector<HostSpec> hosts;  // empty: everything runs where the launcher runs
  std::vector<StageSpec> processes;

  template <class V>
  void visit(V& v) {
    v("lcm_url", lcm_url);
    v("hosts", hosts);
    v("processes", processes);
  }

  // The host of a process (its own, or the first host), nullptr when there are no hosts.
  const HostSpec* host_of(const StageSpec& s) const;
  const HostSpec* find_host(const std::string& name) const;
};

// Loads and checks a deployment file (unknown keys, missing or duplicate names, missing
// programs, unknown hosts or policies); throws ConfigError naming the file and the problem.
// Every process's `host` is filled in (the first host when it names none).
Deployment load_deployment(const std::string& path);

// The stages named in `list` (names separated by commas; "all" stands for every stage not marked
// optional) in deployment order; nullopt and `error` set when a name is not in the deployment.
std::optional<std::vector<StageSpec>> select_stages(const Deployment& d, const std::string& list,
                                                    std::string& error);

// A UDP port reserved for one run: a lock file held open (released when this object or the
// process dies) and a port no socket on this host was bound to when it was chosen.
class PortLease {
 public:
  PortLease() = default;
  PortLease(int port, int lock_fd) : port_(port), lock_fd_(lock_fd) {}
  PortLease(PortLease&& o) noexcept;
  PortLease& operator=(PortLease&& o) noexcept;
  PortLease(const PortLease&) = delete;
  PortLease& operator=(const PortLease&) = delete;
  ~PortLease();
  int port() const { return port_; }

 private:
  int port_ = 0;
  int lock_fd_ = -1;
};

// Reserves a port in [first_port, last_port], starting at a random place. Locks live in
// `lock_dir`. nullopt when every port is taken.
std::optional<PortLease> reserve_port(const std::string& lock_dir, int first_port, int last_port);

// `arg` with every "{out}" replaced by `out_dir`.
std::string expand_out_dir(const std::string& arg, const std::string& out_dir);

// The processes a launcher acting as `host` starts: its own and those of hosts with a network
// namespace. With no hosts in the deployment, all of them.
std::vector<StageSpec> started_here(const Deployment& d, const std::vector<StageSpec>& stages,
                                    const std::string& host);

// udpm URL of a run: loopback-only multicast (ttl=0) on `port` with a large receive buffer.
std::string private_url(int port, int recv_buf_bytes);

// The recv_buf_size of an LCM URL [bytes], 0 if it has none.
long recv_buf_size_of(const std::string& url);

}  // namespace traverse::launch
