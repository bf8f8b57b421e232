// Configuration of the handover between frontends (handover.hpp): a frontend swapped in while the
// graph runs, and a session resumed from its saved state. FrontendConfig::handover.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "channels.hpp"

namespace traverse::frontend {

struct HandoverConfig {
  std::string control_channel = channels::kFrontendControl;  // frontend_control_t requests
  // The scans of the last window_s [s] of data (at most max_scans) are kept with the poses the
  // node published for them: a frontend swapped in re-tracks them to build its map. Hector to
  // ICP at the midpoint of 40 s of office-s2 (ideal profile): position RMSE 1.39 mm with 2 s,
  // 0.96 mm with 10 s, 1.02 mm with 20 s (scripts/frontend-swap.sh). 10 s of a 47.7 Hz scanner
  // of 8,536 beams hold 16 MB and take about 0.6 s to re-track.
  double window_s = 10.0;
  int max_scans = 1000;
  // A resumed session's first check_scans scans are checked against the saved scans: at least
  // min_fit of their points must lie within fit_distance_m [m] of a saved point, else the
  // frontend is not where the saved state says (the platform was moved, another site) and the
  // program stops with an error instead of mapping into the old map at a wrong place.
  int check_scans = 3;
  double fit_distance_m = 0.1;
  double min_fit = 0.5;
  // With a state directory (traverse-frontend --state-dir) the window is saved this often [s of
  // data] and at the end; 0: only at the end.
  double save_period_s = 5.0;

  template <class V>
  void visit(V& v) {
    v("control_channel", control_channel);
    v("window_s", window_s);
    v("max_scans", max_scans);
    v("check_scans", check_scans);
    v("fit_distance_m", fit_distance_m);
    v("min_fit", min_fit);
    v("save_period_s", save_period_s);
  }
};

std::optional<std::string> validate(const HandoverConfig& config);

}  // namespace traverse::frontend
