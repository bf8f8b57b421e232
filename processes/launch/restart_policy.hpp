// What the launcher does when a process of the graph dies (ends on its own with a failure), as
// the deployment file says per process (StageSpec::on_death): report it and go on without it,
// restart it after a short delay (at most max_restarts times, then give up and go on without
// it), or stop the whole graph. A process asked to stop is never restarted.
#pragma once

#include <chrono>
#include <map>
#include <string>
#include <vector>

#include "deployment.hpp"
#include "supervisor.hpp"

namespace traverse::launch {

class RestartPolicy {
 public:
  using Clock = std::chrono::steady_clock;

  explicit RestartPolicy(const std::vector<StageSpec>& stages);

  // Children that just ended (Supervisor::reap), seen at `now`: deaths are recorded in events()
  // and restarts scheduled; a death under "stop_graph" sets stop_graph().
  void ended(const std::vector<const Child*>& children, Clock::time_point now);

  // Restarts the processes whose delay has passed; a restart that fails is an event and a
  // death given up on.
  void restart_due(Supervisor& sup, Clock::time_point now);

  // An event from elsewhere (a command carried out), in order with the others.
  void note(const std::string& event) { events_.push_back(event); }

  // No more restarts (the graph is stopping).
  void cancel() { due_.clear(); }

  bool stop_graph() const { return !stopped_by_.empty(); }
  const std::string& stopped_by() const { return stopped_by_; }
  // One sentence per death, restart and surrender, in order, e.g.
  // "densifier died (killed by SIGKILL); restart 1 of 3 in 0.5 s".
  const std::vector<std::string>& events() const { return events_; }

 private:
  std::map<std::string, StageSpec> stages_;
  std::map<std::string, int> restarts_;
  std::map<std::string, Clock::time_point> due_;
  std::vector<std::string> events_;
  std::string stopped_by_;
};

}  // namespace traverse::launch
