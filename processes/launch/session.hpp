// Mapping sessions: the processes that keep state (traverse-backend, traverse-frontend with
// --state-dir "{out}/state/<name>" in the deployment file) write it under OUTDIR/state/. A run
// starts a new session (OUTDIR/state/ cleared), or, with --resume EARLIER_OUT, continues the
// session that EARLIER_OUT saved: its state/ is copied into the new OUTDIR, so the earlier run's
// files (its run.lcmlog, exports and the state as it ended) stay as they were. A process
// restarted within a run (on_death: restart) finds the state of the same run.
#pragma once

#include <optional>
#include <string>

namespace traverse::launch {

// Prepares OUTDIR/state for a run; a problem in words (no state in EARLIER_OUT, EARLIER_OUT being
// OUTDIR itself, a copy that failed), nullopt when ready.
std::optional<std::string> prepare_state(const std::string& out_dir, const std::string& resume);

}  // namespace traverse::launch
