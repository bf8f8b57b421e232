#include "supervisor.hpp"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <thread>

extern char** environ;

namespace traverse::launch {
namespace {

std::string signal_name(int sig) {
  const char* abbrev = sigabbrev_np(sig);
  return abbrev ? std::string("SIG") + abbrev : "signal " + std::to_string(sig);
}

// In the child after fork: only async-signal-safe calls until exec.
[[noreturn]] void exec_child(const std::vector<char*>& argv, const std::vector<char*>& envp,
                             const char* log_path, int log_flags, int netns_fd, pid_t parent) {
  setpgid(0, 0);
  prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (getppid() != parent) _exit(126);  // the launcher is already gone
  struct sigaction sa {};
  sa.sa_handler = SIG_DFL;
  sigemptyset(&sa.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGCHLD}) sigaction(sig, &sa, nullptr);
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  const int in = open("/dev/null", O_RDONLY);
  const int out = open(log_path, O_WRONLY | O_CREAT | log_flags, 0644);
  if (in >= 0) dup2(in, STDIN_FILENO);
  if (out >= 0) {
    dup2(out, STDOUT_FILENO);
    dup2(out, STDERR_FILENO);
  }
  if (netns_fd >= 0 && setns(netns_fd, CLONE_NEWNET) != 0) {
    const char* msg = "launcher: cannot enter the network namespace\n";
    (void)!write(STDERR_FILENO, msg, strlen(msg));
    _exit(126);
  }
  close_range(3, ~0U, 0);
  execve(argv[0], argv.data(), envp.data());
  const char* msg = "launcher: cannot execute ";
  (void)!write(STDERR_FILENO, msg, strlen(msg));
  (void)!write(STDERR_FILENO, argv[0], strlen(argv[0]));
  (void)!write(STDERR_FILENO, "\n", 1);
  _exit(127);
}

}  // namespace

bool enter_netns(const std::string& netns, std::string& error) {
  const std::string path = "/run/netns/" + netns;
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  const bool ok = fd >= 0 && setns(fd, CLONE_NEWNET) == 0;
  if (!ok) error = "cannot enter network namespace " + path + ": " + std::strerror(errno);
  if (fd >= 0) close(fd);
  return ok;
}

bool Child::died() const {
  if (running) return false;
  if (term_signal != 0) return !asked_to_stop;
  return exit_code != 0;
}

std::string Child::outcome() const {
  if (running) return "running";
  std::string s =
      term_signal ? "killed by " + signal_name(term_signal) : "exit " + std::to_string(exit_code);
  if (asked_to_stop)
    s += " after " + last_signal_sent;
  else
    s += exit_code == 0 && term_signal == 0 ? " (ended on its own)" : " (died)";
  return s;
}

Supervisor::~Supervisor() {
  for (auto& c : children_) {
    if (c.running) {
      kill(c.pid, SIGKILL);
      waitpid(c.pid, nullptr, 0);
    }
  }
}

bool Supervisor::start(Child& c, bool append_log, std::string& error) {
  std::vector<char*> cargv;
  for (const auto& a : c.argv) cargv.push_back(const_cast<char*>(a.c_str()));
  cargv.push_back(nullptr);
  // The environment, with TRAVERSE_HOST replaced: built before fork (no allocation after it).
  std::vector<std::string> env_strings;
  for (char** e = environ; e && *e; ++e) {
    if (std::strncmp(*e, "TRAVERSE_HOST=", 14) != 0) env_strings.emplace_back(*e);
  }
  if (!c.host.empty()) env_strings.push_back("TRAVERSE_HOST=" + c.host);
  std::vector<char*> envp;
  for (auto& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);
  int netns_fd = -1;
  if (!c.netns.empty()) {
    const std::string path = "/run/netns/" + c.netns;
    netns_fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (netns_fd < 0) {
      error = "cannot open network namespace " + path + " for '" + c.name +
              "': " + std::strerror(errno);
      return false;
    }
  }
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    error = std::string("fork failed: ") + std::strerror(errno);
    if (netns_fd >= 0) close(netns_fd);
    return false;
  }
  if (pid == 0) {
    exec_child(cargv, envp, c.log_path.c_str(), append_log ? O_APPEND : O_TRUNC, netns_fd, parent);
  }
  if (netns_fd >= 0) close(netns_fd);
  setpgid(pid, pid);  // also here, so signals to the group work even before the child runs
  c.pid = pid;
  c.running = true;
  c.asked_to_stop = false;
  c.exit_code = -1;
  c.term_signal = 0;
  c.last_signal_sent.clear();
  return true;
}

bool Supervisor::spawn(const std::string& name, const std::vector<std::string>& argv,
                       const std::string& log_path, std::string& error, const std::string& host,
                       const std::string& netns) {
  Child c;
  c.name = name;
  c.argv = argv;
  c.log_path = log_path;
  c.host = host;
  c.netns = netns;
  if (!start(c, false, error)) return false;
  children_.push_back(std::move(c));
  return true;
}

bool Supervisor::respawn(const std::string& name, std::string& error) {
  for (auto& c : children_) {
    if (c.name != name) continue;
    if (c.running) return true;
    if (!start(c, true, error)) return false;
    ++c.restarts;
    return true;
  }
  error = "no process '" + name + "' to restart";
  return false;
}

std::vector<const Child*> Supervisor::reap() {
  std::vector<const Child*> ended;
  for (auto& c : children_) {
    if (!c.running) continue;
    int status = 0;
    if (waitpid(c.pid, &status, WNOHANG) != c.pid) continue;
    c.running = false;
    if (WIFEXITED(status)) c.exit_code = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) c.term_signal = WTERMSIG(status);
    ended.push_back(&c);
  }
  return ended;
}

const Child* Supervisor::find(const std::string& name) const {
  for (const auto& c : children_) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

void Supervisor::signal_running(const std::vector<std::string>& names, int sig,
                                const char* sig_name) {
  for (auto& c : children_) {
    bool named = false;
    for (const auto& n : names) named = named || n == c.name;
    if (!named || !c.running) continue;
    c.asked_to_stop = true;
    c.last_signal_sent = sig_name;
    kill(c.pid, sig);
  }
}

bool Supervisor::wait_for(const std::vector<std::string>& names, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (true) {
    reap();
    bool any = false;
    for (const auto& n : names) {
      const Child* c = find(n);
      any = any || (c && c->running);
    }
    if (!any) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

void Supervisor::stop(const std::vector<std::string>& names, double timeout_s) {
  signal_running(names, SIGINT, "SIGINT");
  if (wait_for(names, timeout_s)) return;
  signal_running(names, SIGTERM, "SIGTERM");
  if (wait_for(names, 2.0)) return;
  signal_running(names, SIGKILL, "SIGKILL");
  wait_for(names, 10.0);
}

}  // namespace traverse::launch
