// The evaluator's outputs: the error time series as CSV, its plot (seed 000 Figure 3 style, drawn
// by scripts/plot_errors.py with matplotlib), and the one-line JSON summary.
#pragma once

#include <optional>
#include <string>

#include "evaluator.hpp"
#include "json.hpp"

namespace traverse::evaluator {

// Writes one row per matched estimate; false if the file cannot be written.
bool write_errors_csv(const Evaluation& ev, const std::string& path);

// Writes one row per loop closure (ids, times, measured and true relative pose, error, standard
// deviations, Mahalanobis distance, false flag, the frontend's error where known); false if the
// file cannot be written.
bool write_closures_csv(const ClosureEvaluation& ev, const std::string& path);

// Runs scripts/plot_errors.py CSV PNG TITLE with the first python3 that has matplotlib. Returns
// nullopt on success, else why there is no plot. The script's output goes to stderr.
std::optional<std::string> plot_errors(const std::string& script, const std::string& csv,
                                       const std::string& png, const std::string& title);

// The summary is one flat JSON object on one line; numbers carry their unit in the key and are
// written with a fixed number of decimals (6 unless said), null when unknown.

// The figures of an evaluation under the keys scripts and later stages rely on.
void add_evaluation(const Evaluation& ev, Json& json);

// The loop-closure figures: always present, counts 0 and figures null when there is no closure.
void add_closures(const ClosureEvaluation& ev, Json& json);

// The loop closures checked by relations (check_closures_by_relations), under the keys README.md's
// closure figures were first published with: closures, checked, window_s, sigmas, bridge_sigma_m,
// bridge_sigma_deg (the frontend's error over a bridge), median_error_m, max_error_m,
// median_error_deg, max_error_deg, median_sigmas, max_sigmas, over_sigmas (false closures),
// frontend_median_error_m, frontend_median_error_deg, closure_nearer (closures nearer the truth
// than the frontend); and closures_bad_covariance. Always present; figures null when no closure
// is checked.
void add_closures_by_relations(const ClosureEvaluation& ev, double window_s, double sigmas,
                               Json& json);

// The relations figures (relations.hpp): counts always, figures null when refused. Keys:
// relations, relations_used, relations_missing, relations_share, refused, trans_{mean,sd,max}_m,
// trans_sq_{mean,sd}_m2, rot_{mean,sd,max}_deg, rot_sq_{mean,sd}_deg2.
void add_relations(const RelationsEvaluation& ev, Json& json);

// One row per relation: stamps, used, the relation and the estimate's relative pose, errors.
bool write_relations_csv(const RelationsEvaluation& ev, const std::string& path);

}  // namespace traverse::evaluator
