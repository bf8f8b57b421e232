// What run-graph starts: a deployment file lists the processes of a graph in graph order,
//
//   processes:
//     - name: frontend                  # instance name; status on STATUS_FRONTEND
//       program: traverse-frontend      # looked up in the build's bin/ (or a path with '/')
//       config: configs/frontend.yaml   # optional; relative paths are from the repository root
//       args: [--out, "{out}/frontend"]  # optional extra arguments; {out} = the run's folder
//       stop_timeout_s: 60              # optional: time it may take to stop (e.g. exports)
//
// and the launcher gives each one its config, --name and the one LCM URL of the run. Also here:
// choosing a private LCM port that no other run on this machine holds at the same time.
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

  template <class V>
  void visit(V& v) {
    v("name", name);
    v("program", program);
    v("config", config);
    v("args", args);
    v("stop_timeout_s", stop_timeout_s);
  }
};

// The first value out of range, named by its key; nullopt when the stage is usable.
std::optional<std::string> validate(const StageSpec& stage);

struct Deployment {
  std::vector<StageSpec> processes;

  template <class V>
  void visit(V& v) {
    v("processes", processes);
  }
};

// Loads and checks a deployment file (unknown keys, missing or duplicate names, missing
// programs); throws ConfigError naming the file and the problem.
Deployment load_deployment(const std::string& path);

// The stages named in `list` ("all", or names separated by commas) in deployment order;
// nullopt and `error` set when a name is not in the deployment.
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

// udpm URL of a run: loopback-only multicast (ttl=0) on `port` with a large receive buffer.
std::string private_url(int port, int recv_buf_bytes);

// The recv_buf_size of an LCM URL [bytes], 0 if it has none.
long recv_buf_size_of(const std::string& url);

}  // namespace traverse::launch
