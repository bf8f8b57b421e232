#include "restart_policy.hpp"

#include <cstdio>

namespace traverse::launch {

RestartPolicy::RestartPolicy(const std::vector<StageSpec>& stages) {
  for (const auto& s : stages) stages_[s.name] = s;
}

void RestartPolicy::ended(const std::vector<const Child*>& children, Clock::time_point now) {
  for (const Child* c : children) {
    const auto it = stages_.find(c->name);
    if (it == stages_.end() || !c->died()) continue;  // the launcher's own helpers, clean ends
    const StageSpec& s = it->second;
    std::string event = c->name + " died (" + c->outcome() + ")";
    if (s.on_death == "stop_graph") {
      if (stopped_by_.empty()) stopped_by_ = c->name;
      event += "; stopping the graph";
    } else if (s.on_death == "restart" && restarts_[c->name] < s.max_restarts) {
      const int n = ++restarts_[c->name];
      char buf[96];
      std::snprintf(buf, sizeof(buf), "; restart %d of %d in %.1f s", n, s.max_restarts,
                    s.restart_delay_s);
      event += buf;
      due_[c->name] = now + std::chrono::duration_cast<Clock::duration>(
                                std::chrono::duration<double>(s.restart_delay_s));
    } else if (s.on_death == "restart") {
      event += "; given up after " + std::to_string(s.max_restarts) + " restart(s)";
    }
    events_.push_back(event);
  }
}

void RestartPolicy::restart_due(Supervisor& sup, Clock::time_point now) {
  for (auto it = due_.begin(); it != due_.end();) {
    if (it->second > now) {
      ++it;
      continue;
    }
    std::string error;
    if (sup.respawn(it->first, error)) {
      events_.push_back(it->first + " restarted (pid " + std::to_string(sup.find(it->first)->pid) +
                        ")");
    } else {
      events_.push_back(it->first + " could not be restarted: " + error);
    }
    it = due_.erase(it);
  }
}

}  // namespace traverse::launch
