// Starts child programs and stops them cleanly: fork/exec with stdout and stderr into a log file,
// each child in its own process group (a terminal's Ctrl-C reaches only the launcher, which then
// stops the children in graph order) and set to receive SIGTERM if the launcher dies.
// Stopping escalates SIGINT -> SIGTERM -> SIGKILL with timeouts. A child may be started inside a
// network namespace (one that stands in for another machine) and restarted after it died.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace traverse::launch {

struct Child {
  std::string name;
  std::vector<std::string> argv;
  std::string log_path;
  std::string host;   // deployment host it runs on ("" when the deployment names none)
  std::string netns;  // network namespace it was started in ("": the launcher's own)
  int restarts = 0;   // times it was started again after dying
  pid_t pid = -1;
  bool running = false;
  bool asked_to_stop = false;    // ended after we signalled it (or while we were stopping it)
  int exit_code = -1;            // when it exited normally
  int term_signal = 0;           // when a signal ended it
  std::string last_signal_sent;  // "SIGINT", "SIGTERM" or "SIGKILL"

  // Ended on its own with a failure: non-zero exit or a signal we did not send.
  bool died() const;
  // Human-readable end, e.g. "exit 0 after SIGINT", "killed by SIGSEGV".
  std::string outcome() const;
};

// Moves the calling process (single-threaded still) into the network namespace `netns` (a name
// under /run/netns); false with `error` set when it cannot.
bool enter_netns(const std::string& netns, std::string& error);

class Supervisor {
 public:
  ~Supervisor();  // SIGKILLs children still running

  // Starts argv[0] (a path) with the remaining arguments; false with `error` set if fork fails
  // or the network namespace `netns` (a name under /run/netns, "" for none) cannot be opened.
  // A program that cannot be executed ends at once with exit code 127 (message in its log).
  // `host` reaches the child as TRAVERSE_HOST (the host name its status reports).
  bool spawn(const std::string& name, const std::vector<std::string>& argv,
             const std::string& log_path, std::string& error, const std::string& host = "",
             const std::string& netns = "");

  // Starts an ended child again with the same command line, appending to its log.
  bool respawn(const std::string& name, std::string& error);

  // Collects children that ended; returns the ones that ended during this call.
  std::vector<const Child*> reap();

  // Stops the named children (all at once): SIGINT, then SIGTERM after `timeout_s`, SIGKILL
  // 2 s later. Returns when all have ended.
  void stop(const std::vector<std::string>& names, double timeout_s);

  const Child* find(const std::string& name) const;
  const std::vector<Child>& children() const { return children_; }

 private:
  void signal_running(const std::vector<std::string>& names, int sig, const char* sig_name);
  bool wait_for(const std::vector<std::string>& names, double timeout_s);
  bool start(Child& c, bool append_log, std::string& error);
  std::vector<Child> children_;
};

}  // namespace traverse::launch
