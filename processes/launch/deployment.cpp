#include "deployment.hpp"

#include <fcntl.h>
#include <netinet/in.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <random>
#include <set>
#include <sstream>

#include "config.hpp"

namespace traverse::launch {

std::optional<std::string> validate(const StageSpec& s) {
  ConfigCheck check;
  check.in_range("stop_timeout_s", s.stop_timeout_s, 0.0, 3600.0);
  check.require(s.on_death == "report" || s.on_death == "restart" || s.on_death == "stop_graph",
                "on_death", "must be report, restart or stop_graph, got '" + s.on_death + "'");
  check.in_range("max_restarts", s.max_restarts, 0, 1000);
  check.in_range("restart_delay_s", s.restart_delay_s, 0.0, 600.0);
  return check.problem();
}

const HostSpec* Deployment::find_host(const std::string& name) const {
  for (const auto& h : hosts) {
    if (h.name == name) return &h;
  }
  return nullptr;
}

const HostSpec* Deployment::host_of(const StageSpec& s) const {
  if (hosts.empty()) return nullptr;
  return s.host.empty() ? &hosts.front() : find_host(s.host);
}

Deployment load_deployment(const std::string& path) {
  Deployment d;
  load_config(path, d);
  std::set<std::string> host_names;
  for (std::size_t i = 0; i < d.hosts.size(); ++i) {
    const std::string where = path + ": hosts[" + std::to_string(i) + "]";
    if (d.hosts[i].name.empty()) throw ConfigError(where + ": key 'name' is missing");
    if (!host_names.insert(d.hosts[i].name).second) {
      throw ConfigError(where + ": name '" + d.hosts[i].name + "' used twice");
    }
  }
  if (!d.lcm_url.empty() && d.lcm_url.rfind("udpm://", 0) != 0 &&
      d.lcm_url.rfind("memq://", 0) != 0) {
    throw ConfigError(path + ": key 'lcm_url' must be a udpm:// (or memq://) URL, got '" +
                      d.lcm_url + "'");
  }
  std::set<std::string> names;
  for (std::size_t i = 0; i < d.processes.size(); ++i) {
    const StageSpec& s = d.processes[i];
    const std::string where = path + ": processes[" + std::to_string(i) + "]";
    if (s.name.empty()) throw ConfigError(where + ": key 'name' is missing");
    if (s.program.empty()) throw ConfigError(where + ": key 'program' is missing");
    if (s.name == "monitor" || s.name == "logger" || s.name == "logplayer") {
      throw ConfigError(where + ": name '" + s.name + "' is reserved for the launcher");
    }
    if (!names.insert(s.name).second) {
      throw ConfigError(where + ": name '" + s.name + "' used twice");
    }
    if (const auto problem = validate(s)) throw ConfigError(where + ": " + *problem);
    if (!s.host.empty() && !d.find_host(s.host)) {
      throw ConfigError(where + ": key 'host': '" + s.host + "' is not one of the hosts");
    }
  }
  for (auto& s : d.processes) {
    if (s.host.empty() && !d.hosts.empty()) s.host = d.hosts.front().name;
  }
  return d;
}

std::vector<StageSpec> started_here(const Deployment& d, const std::vector<StageSpec>& stages,
                                    const std::string& host) {
  std::vector<StageSpec> out;
  for (const auto& s : stages) {
    const HostSpec* h = d.host_of(s);
    if (!h || h->name == host || !h->netns.empty()) out.push_back(s);
  }
  return out;
}

std::optional<std::vector<StageSpec>> select_stages(const Deployment& d, const std::string& list,
                                                    std::string& error) {
  std::set<std::string> wanted;
  bool all = list.empty();
  std::stringstream ss(list);
  for (std::string name; std::getline(ss, name, ',');) {
    if (name.empty()) continue;
    if (name == "all") {
      all = true;
      continue;
    }
    bool known = false;
    for (const auto& s : d.processes) known = known || s.name == name;
    if (!known) {
      error = "stage '" + name + "' is not in the deployment";
      return std::nullopt;
    }
    wanted.insert(name);
  }
  std::vector<StageSpec> out;
  for (const auto& s : d.processes) {
    if (wanted.count(s.name) || (all && !s.optional)) out.push_back(s);
  }
  return out;
}

PortLease::PortLease(PortLease&& o) noexcept : port_(o.port_), lock_fd_(o.lock_fd_) {
  o.lock_fd_ = -1;
}

PortLease& PortLease::operator=(PortLease&& o) noexcept {
  if (this != &o) {
    if (lock_fd_ >= 0) close(lock_fd_);
    port_ = o.port_;
    lock_fd_ = o.lock_fd_;
    o.lock_fd_ = -1;
  }
  return *this;
}

PortLease::~PortLease() {
  if (lock_fd_ >= 0) close(lock_fd_);  // closing releases the flock
}

namespace {

// True if nothing on this host is bound to UDP `port` right now. The probe does not set
// SO_REUSEADDR, so it fails against LCM's own sockets, which do.
bool udp_port_free(int port) {
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_ANY);
  addr.sin_port = htons(static_cast<uint16_t>(port));
  const bool ok = bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0;
  close(fd);
  return ok;
}

}  // namespace

std::optional<PortLease> reserve_port(const std::string& lock_dir, int first_port, int last_port) {
  std::error_code ec;
  std::filesystem::create_directories(lock_dir, ec);
  // World-writable like /tmp, so runs by different users share one set of locks.
  std::filesystem::permissions(lock_dir, std::filesystem::perms::all, ec);
  const int span = last_port - first_port + 1;
  if (span <= 0) return std::nullopt;
  std::random_device rd;
  const int start = static_cast<int>(rd() % static_cast<unsigned>(span));
  for (int k = 0; k < span; ++k) {
    const int port = first_port + (start + k) % span;
    const std::string lock_path = lock_dir + "/" + std::to_string(port) + ".lock";
    const int fd = open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
      close(fd);
      continue;
    }
    if (!udp_port_free(port)) {
      close(fd);
      continue;
    }
    return PortLease(port, fd);
  }
  return std::nullopt;
}

std::string private_url(int port, int recv_buf_bytes) {
  return "udpm://239.255.76.67:" + std::to_string(port) +
         "?ttl=0&recv_buf_size=" + std::to_string(recv_buf_bytes);
}

long recv_buf_size_of(const std::string& url) {
  const std::string key = "recv_buf_size=";
  const auto at = url.find(key);
  if (at == std::string::npos) return 0;
  try {
    return std::stol(url.substr(at + key.size()));
  } catch (const std::exception&) {
    return 0;
  }
}

std::string expand_out_dir(const std::string& arg, const std::string& out_dir) {
  static const std::string kToken = "{out}";
  std::string r = arg;
  for (auto pos = r.find(kToken); pos != std::string::npos; pos = r.find(kToken, pos)) {
    r.replace(pos, kToken.size(), out_dir);
    pos += out_dir.size();
  }
  return r;
}

}  // namespace traverse::launch
