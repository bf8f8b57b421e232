// The evaluator's outputs: the error time series as CSV, its plot (seed 000 Figure 3 style, drawn
// by scripts/plot_errors.py with matplotlib), and the one-line JSON summary.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "evaluator.hpp"

namespace traverse::evaluator {

// Writes one row per matched estimate; false if the file cannot be written.
bool write_errors_csv(const Evaluation& ev, const std::string& path);

// Writes one row per loop closure (ids, times, measured and true relative pose, error, standard
// deviations, Mahalanobis distance, false flag); false if the file cannot be written.
bool write_closures_csv(const ClosureEvaluation& ev, const std::string& path);

// Runs scripts/plot_errors.py CSV PNG TITLE with the first python3 that has matplotlib. Returns
// nullopt on success, else why there is no plot. The script's output goes to stderr.
std::optional<std::string> plot_errors(const std::string& script, const std::string& csv,
                                       const std::string& png, const std::string& title);

// A flat JSON object on one line, built key by key; numbers carry their unit in the key.
class JsonLine {
 public:
  JsonLine& add(const std::string& key, const std::string& value);        // a string
  JsonLine& add(const std::string& key, double value, int decimals = 6);  // null if not finite
  JsonLine& add(const std::string& key, std::optional<double> value, int decimals = 6);
  JsonLine& add_int(const std::string& key, long long value);
  JsonLine& add_bool(const std::string& key, bool value);
  JsonLine& add_null(const std::string& key);
  std::string str() const;

 private:
  std::vector<std::pair<std::string, std::string>> fields_;  // key, encoded value
};

// The figures of an evaluation under the keys scripts and later stages rely on.
void add_evaluation(const Evaluation& ev, JsonLine& json);

// The loop-closure figures: always present, counts 0 and figures null when there is no closure.
void add_closures(const ClosureEvaluation& ev, JsonLine& json);

// The relations figures (relations.hpp): counts always, figures null when refused. Keys:
// relations, relations_used, relations_missing, relations_share, refused, trans_{mean,sd,max}_m,
// trans_sq_{mean,sd}_m2, rot_{mean,sd,max}_deg, rot_sq_{mean,sd}_deg2.
void add_relations(const RelationsEvaluation& ev, JsonLine& json);

// One row per relation: stamps, used, the relation and the estimate's relative pose, errors.
bool write_relations_csv(const RelationsEvaluation& ev, const std::string& path);

}  // namespace traverse::evaluator
