// traverse-evaluator: compares a trajectory channel with ground truth or reference poses, offline
// on an LCM log (--log) or live in the graph (outputs written at SIGINT/SIGTERM). The estimate
// channel may carry pose2d_t, or the backend's key_poses_t or the densifier's dense_segments_t,
// whose final (newest) revision is evaluated. The backend's loop closures are checked against the
// reference, or with --relations against the relations, bridged by the frontend's poses. Writes
// errors.csv, errors.png and closures.csv (relations.csv and closures.csv with --relations) under
// --out and prints one JSON summary line last.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "channels.hpp"
#include "evaluator.hpp"
#include "pose_collector.hpp"
#include "process.hpp"
#include "report.hpp"

namespace {

namespace ev = traverse::evaluator;
using traverse::Json;
using traverse::json_fixed;
using traverse::json_line;
namespace fs = std::filesystem;

struct Options {
  std::string log;
  std::string estimate = traverse::channels::kPoseFrontend;
  std::string reference = traverse::channels::kPoseGroundTruth;
  std::string out;
  std::string align;
  std::vector<double> shift;  // dx [m], dy [m], dtheta [rad]
  std::string relations;      // a .relations file: score by relations instead (relations.hpp)
  // [s] --relations: how far a relation's scan may lie from a closure's key pose to check it.
  double closure_window_s = 2.0;
  double false_closure_sigmas = 0.0;  // > 0: overrides the config's
};

// Offline runs must not need a network: look for --log before the process connects to LCM.
bool has_log_option(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--log") == 0 || std::strncmp(argv[i], "--log=", 6) == 0) return true;
  }
  return false;
}

void add_options(CLI::App& app, Options& opt) {
  app.add_option("--log", opt.log, "evaluate this LCM log offline instead of listening live")
      ->check(CLI::ExistingFile);
  app.add_option("--estimate", opt.estimate,
                 "channel of the estimated trajectory: pose2d_t, key_poses_t or dense_segments_t")
      ->capture_default_str();
  app.add_option("--reference", opt.reference,
                 "pose2d_t channel of the reference (ground truth or reference poses)")
      ->capture_default_str();
  app.add_option("--out", opt.out,
                 "directory for errors.csv, errors.png and closures.csv (relations.csv and "
                 "closures.csv with --relations)");
  app.add_option("--relations", opt.relations,
                 "score the estimate by the relations in FILE (Kuemmerle et al. 2009: t1 t2 dx dy "
                 "dz droll dpitch dyaw per line) instead of against --reference")
      ->check(CLI::ExistingFile);
  app.add_option("--closure-window-s", opt.closure_window_s,
                 "with --relations: check a loop closure by a relation with a scan within this "
                 "many seconds of each key pose, bridged by the frontend's poses (POSE_FRONTEND)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--false-closure-sigmas", opt.false_closure_sigmas,
                 "override the config's false_closure_sigmas: a loop closure farther from the "
                 "truth than this many standard deviations is false")
      ->check(CLI::PositiveNumber);
  app.add_option("--align", opt.align, "override the config's align: none, first_pose or se2")
      ->check(CLI::IsMember({"none", "first_pose", "se2"}));
  app.add_option("--shift-estimate", opt.shift,
                 "DX DY DTHETA: add [m], [m], [rad] to every estimate pose first (a known error "
                 "to check the evaluator with; use --align none)")
      ->expected(3)
      ->allow_extra_args(false);
}

// closures.csv under --out (created), its path in the JSON; false when it cannot be written.
bool write_closures(const Options& opt, const ev::ClosureEvaluation& closures, Json& json) {
  std::error_code ec;
  fs::create_directories(opt.out, ec);
  const std::string csv = (fs::path(opt.out) / "closures.csv").string();
  if (!ev::write_closures_csv(closures, csv)) {
    spdlog::error("traverse-evaluator: cannot write {}", csv);
    return false;
  }
  json["closures_csv"] = csv;
  return true;
}

// closures.csv, errors.csv and errors.png under --out, their paths (or why there is no plot) in
// the JSON.
bool write_outputs(const Options& opt, const ev::Evaluation& evaluation,
                   const ev::ClosureEvaluation& closures, Json& json) {
  if (!write_closures(opt, closures, json)) return false;
  const std::string csv = (fs::path(opt.out) / "errors.csv").string();
  const std::string png = (fs::path(opt.out) / "errors.png").string();
  if (!ev::write_errors_csv(evaluation, csv)) {
    spdlog::error("traverse-evaluator: cannot write {}", csv);
    return false;
  }
  json["errors_csv"] = csv;
  if (evaluation.matched == 0) {
    json["errors_png"] = nullptr;
    json["plot_note"] = "nothing matched, nothing to plot";
    return true;
  }
  const double rmse_m = evaluation.position_m.rmse;
  const std::string title = fmt::format(
      "{} vs {} (align {}): position RMSE {}, heading RMSE {:.3f} deg", opt.estimate, opt.reference,
      ev::align_name(evaluation.alignment.used),
      rmse_m < 1.0 ? fmt::format("{:.1f} mm", 1e3 * rmse_m) : fmt::format("{:.3f} m", rmse_m),
      180.0 / M_PI * evaluation.heading_rad.rmse);
  const auto plot_problem = ev::plot_errors(
      std::string(TRAVERSE_SOURCE_DIR) + "/scripts/plot_errors.py", csv, png, title);
  if (plot_problem) {
    spdlog::warn("traverse-evaluator: {}", *plot_problem);
    json["errors_png"] = nullptr;
    json["plot_note"] = *plot_problem;
  } else {
    json["errors_png"] = png;
  }
  return true;
}

// The JSON fields every mode reports about the estimate channel and the log it was read from.
void add_input_facts(const Options& opt, const ev::PoseCollector& collector, bool offline,
                     const ev::PoseCollector::LogSummary& log_summary, Json& json) {
  const std::string type = ev::estimate_type_name(collector.estimate_type());
  json["estimate_channel"] = opt.estimate;
  json["estimate_type"] = type.empty() ? Json() : Json(type);
  json["non_finite_poses"] = collector.non_finite_poses();
  json["decode_failures"] = collector.decode_failures();
  json["mixed_type_messages"] = collector.mixed_type_messages();
  if (offline) {
    json["log"] = opt.log;
    json["log_damaged_records"] = log_summary.damaged_records;
  }
}

// --relations: the estimate scored by the relations; exit 1 when the figures are refused.
int score_relations(const Options& opt, const ev::EvaluatorConfig& cfg,
                    const ev::RelationsFile& file, const ev::Trajectory& estimate, Json& json) {
  const ev::RelationsEvaluation r = ev::evaluate_relations(
      estimate, file.relations, {cfg.relation_time_tolerance_us, cfg.min_reference_share});
  json["mode"] = "relations";
  json["relations_file"] = opt.relations;
  ev::add_relations(r, json);
  json["min_reference_share"] = json_fixed(cfg.min_reference_share, 3);
  json["relation_time_tolerance_us"] = cfg.relation_time_tolerance_us;
  json["relations_malformed_lines"] = file.malformed_count;
  json["estimate_poses"] = estimate.size();
  if (r.refused) {
    spdlog::error(
        "traverse-evaluator: {} of {} relations ({:.1f} %) have a pose on {} at both scans' "
        "stamps, below min_reference_share {:.0f} %: no figures",
        r.used, r.relations, 100.0 * r.share, opt.estimate, 100.0 * cfg.min_reference_share);
  }
  if (!opt.out.empty()) {
    std::error_code ec;
    fs::create_directories(opt.out, ec);
    const std::string csv = (fs::path(opt.out) / "relations.csv").string();
    if (!ev::write_relations_csv(r, csv)) {
      spdlog::error("traverse-evaluator: cannot write {}", csv);
      return 1;
    }
    json["relations_csv"] = csv;
  }
  return r.refused ? 1 : 0;
}

// --relations: the loop closures checked by the relations (check_closures_by_relations), bridged
// by the frontend's poses; closures.csv under --out. False when the file cannot be written.
bool report_closures_by_relations(const Options& opt, const ev::EvaluatorConfig& cfg,
                                  const ev::RelationsFile& file, const ev::PoseCollector& collector,
                                  Json& json) {
  if (collector.frontend().empty() && collector.closures().size() > 0) {
    spdlog::warn(
        "traverse-evaluator: no pose on {}: the loop closures cannot be checked by the "
        "relations",
        traverse::channels::kPoseFrontend);
  }
  const ev::ClosureEvaluation closures = ev::check_closures_by_relations(
      collector.closures().closures(), collector.frontend(), file.relations,
      std::llround(1e6 * opt.closure_window_s), cfg.false_closure_sigmas);
  ev::add_closures_by_relations(closures, opt.closure_window_s, cfg.false_closure_sigmas, json);
  json["frontend_channel"] = traverse::channels::kPoseFrontend;
  json["frontend_poses"] = collector.frontend().size();
  return opt.out.empty() || write_closures(opt, closures, json);
}

// A channel carrying several types is an error of the graph, not of the figures: say so loudly.
void report_type_problems(const ev::PoseCollector& collector, const std::string& estimate_channel) {
  if (collector.mixed_type_messages() == 0) return;
  std::string types;
  for (const std::string& t : collector.estimate_types_seen()) {
    types += (types.empty() ? "" : ", ") + t;
  }
  spdlog::error(
      "traverse-evaluator: {} message(s) of an unexpected type dropped on the estimate or "
      "reference channel (estimate channel {} carried {}; its type is taken as {})",
      collector.mixed_type_messages(), estimate_channel, types.empty() ? "nothing" : types,
      collector.estimate_type() == ev::EstimateType::kNone
          ? "none"
          : ev::estimate_type_name(collector.estimate_type()));
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_default_logger(spdlog::stderr_color_mt("evaluator"));
  traverse::Process proc("evaluator",
                         "Compares a trajectory channel with ground truth or reference poses "
                         "(seed 000 Table 2 figures, relative pose error, largest jump).");
  Options opt;
  add_options(proc.cli(), opt);
  ev::EvaluatorConfig cfg;
  const bool offline = has_log_option(argc, argv);
  if (auto rc = proc.start(argc, argv, cfg, !offline)) return *rc;
  if (!opt.align.empty()) cfg.align = opt.align;
  if (opt.false_closure_sigmas > 0.0) cfg.false_closure_sigmas = opt.false_closure_sigmas;
  if (auto error = ev::validate(cfg)) {
    spdlog::error("traverse-evaluator: config error: {} (in {})", *error,
                  proc.config_path().empty() ? "defaults" : proc.config_path());
    return traverse::kConfigErrorExitCode;
  }

  ev::RelationsFile relations;
  if (!opt.relations.empty()) {
    relations = ev::read_relations(opt.relations);
    if (!relations.error.empty()) {
      spdlog::error("traverse-evaluator: {}", relations.error);
      return 1;
    }
    if (relations.malformed_count > 0) {
      spdlog::warn("traverse-evaluator: {}: {} malformed line(s) skipped, the first line {}",
                   opt.relations, relations.malformed_count, relations.malformed_lines.front());
    }
  }

  // The frontend's poses bridge loop closures to relations; without relations they are not used.
  ev::PoseCollector collector(opt.estimate, opt.reference, cfg.key_poses_channel,
                              opt.relations.empty() ? "" : traverse::channels::kPoseFrontend);
  ev::PoseCollector::LogSummary log_summary;
  if (offline) {
    try {
      log_summary = collector.read_log(opt.log);
    } catch (const std::runtime_error& e) {
      spdlog::error("traverse-evaluator: {}", e.what());
      return 1;
    }
  } else {
    collector.subscribe(proc.bus());
    const int rc = proc.spin([&] {
      proc.counter("estimate_poses") = static_cast<double>(collector.estimate_size());
      proc.counter("reference_poses") = static_cast<double>(collector.reference().size());
      proc.counter("loop_closures") = static_cast<double>(collector.closures().size());
      proc.counter("decode_failures") = static_cast<double>(collector.decode_failures());
      proc.counter("mixed_type_messages") = static_cast<double>(collector.mixed_type_messages());
    });
    if (rc != 0) return rc;
  }

  ev::Trajectory estimate = collector.estimate();
  if (opt.shift.size() == 3) ev::shift(estimate, opt.shift[0], opt.shift[1], opt.shift[2]);
  report_type_problems(collector, opt.estimate);
  Json json;
  if (!opt.relations.empty()) {
    int rc = score_relations(opt, cfg, relations, estimate, json);
    if (!report_closures_by_relations(opt, cfg, relations, collector, json)) rc = 1;
    add_input_facts(opt, collector, offline, log_summary, json);
    std::cout << json_line(json) << std::endl;
    return rc;
  }

  const ev::Evaluation evaluation = ev::evaluate(estimate, collector.reference(), cfg);
  const ev::ClosureEvaluation closures = ev::check_closures(
      collector.closures().closures(), collector.reference(), cfg.match, cfg.false_closure_sigmas);
  ev::add_evaluation(evaluation, json);
  json["min_reference_share"] = json_fixed(cfg.min_reference_share, 3);
  ev::add_closures(closures, json);
  add_input_facts(opt, collector, offline, log_summary, json);
  json["reference_channel"] = opt.reference;
  json["key_poses_channel"] = cfg.key_poses_channel;
  json["key_pose_revisions"] = collector.key_poses().replaced();
  json["dense_segments"] = collector.dense().size();
  int rc = 0;
  if (evaluation.matched == 0) {
    spdlog::error(
        "traverse-evaluator: no estimate pose on {} matched a pose on {} ({} and {} poses)",
        opt.estimate, opt.reference, evaluation.estimate_poses, evaluation.reference_poses);
    rc = 1;
  } else if (evaluation.refused) {
    spdlog::error(
        "traverse-evaluator: the {} matched poses of {} cover {} of the {} poses on {} ({:.1f} "
        "%), below min_reference_share {:.0f} %: no figures",
        evaluation.matched, opt.estimate, evaluation.reference_covered, evaluation.reference_poses,
        opt.reference, 100.0 * evaluation.reference_share, 100.0 * cfg.min_reference_share);
    rc = 1;
  }
  if (!opt.out.empty() && !write_outputs(opt, evaluation, closures, json)) return 1;
  std::cout << json_line(json) << std::endl;
  return rc;
}
