// The operator's command to swap the frontend of a running graph:
//
//   scripts/run-graph.sh --out OUTDIR --control frontend --kind icp [--process frontend]
//
// sends frontend_control_t requests on FRONTEND_CONTROL over the run's LCM URL (OUTDIR/lcm_url,
// written by the launcher) and repeats the same request (one request_id) every 200 ms until the
// frontend's status (STATUS_<PROCESS>) shows it carried out: frontend_request_id at the request's
// id and frontend_kind_icp saying the kind. A request lost on the way is thus sent again, and one
// that is never carried out is an error (exit 1, the kind the status still shows), not silence.
// There is one frontend process, which holds one frontend at a time: a lost request leaves the
// old frontend running, never two or none (docs/frontends.md).
#pragma once

#include <filesystem>
#include <string>

namespace traverse::launch {

// Exit code: 0 carried out, 1 not within timeout_s (or no run in OUTDIR), 2 a bad kind.
int send_frontend_control(const std::filesystem::path& out_dir, const std::string& process,
                          const std::string& kind, double timeout_s);

}  // namespace traverse::launch
