#include "supervisor.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <thread>

namespace traverse::launch {
namespace {

std::string signal_name(int sig) {
  const char* abbrev = sigabbrev_np(sig);
  return abbrev ? std::string("SIG") + abbrev : "signal " + std::to_string(sig);
}

// In the child after fork: only async-signal-safe calls until exec.
[[noreturn]] void exec_child(const std::vector<char*>& argv, const char* log_path, pid_t parent) {
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
  const int out = open(log_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (in >= 0) dup2(in, STDIN_FILENO);
  if (out >= 0) {
    dup2(out, STDOUT_FILENO);
    dup2(out, STDERR_FILENO);
  }
  close_range(3, ~0U, 0);
  execv(argv[0], argv.data());
  const char* msg = "launcher: cannot execute ";
  (void)!write(STDERR_FILENO, msg, strlen(msg));
  (void)!write(STDERR_FILENO, argv[0], strlen(argv[0]));
  (void)!write(STDERR_FILENO, "\n", 1);
  _exit(127);
}

}  // namespace

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

bool Supervisor::spawn(const std::string& name, const std::vector<std::string>& argv,
                       const std::string& log_path, std::string& error) {
  std::vector<char*> cargv;
  for (const auto& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
  cargv.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    error = std::string("fork failed: ") + std::strerror(errno);
    return false;
  }
  if (pid == 0) exec_child(cargv, log_path.c_str(), parent);
  setpgid(pid, pid);  // also here, so signals to the group work even before the child runs
  Child c;
  c.name = name;
  c.argv = argv;
  c.log_path = log_path;
  c.pid = pid;
  c.running = true;
  children_.push_back(std::move(c));
  return true;
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
