#include "report.hpp"

#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "json_escape.hpp"

namespace traverse::evaluator {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;
// Exit code of plot_errors.py when matplotlib cannot be imported.
constexpr int kNoMatplotlibExitCode = 3;

// Runs argv with stdout sent to stderr; the exit code, or -1 if it could not be run.
int run(const std::vector<std::string>& args) {
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    dup2(STDERR_FILENO, STDOUT_FILENO);  // our stdout ends with the JSON line alone
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

}  // namespace

bool write_errors_csv(const Evaluation& ev, const std::string& path) {
  std::ofstream out(path);
  if (!out) return false;
  out << "utime_us,time_s,travel_m,position_error_m,heading_error_deg,"
         "est_x_m,est_y_m,est_theta_deg,ref_x_m,ref_y_m,ref_theta_deg\n";
  const int64_t t0 = ev.samples.empty() ? 0 : ev.samples.front().utime;
  for (const ErrorSample& s : ev.samples) {
    out << fmt::format("{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}\n",
                       s.utime, 1e-6 * static_cast<double>(s.utime - t0), s.travel_m,
                       s.position_error_m, kDegPerRad * s.heading_error_rad, s.T_ref_est.x(),
                       s.T_ref_est.y(), kDegPerRad * s.T_ref_est.theta(), s.T_ref_true.x(),
                       s.T_ref_true.y(), kDegPerRad * s.T_ref_true.theta());
  }
  return static_cast<bool>(out.flush());
}

bool write_closures_csv(const ClosureEvaluation& ev, const std::string& path) {
  std::ofstream out(path);
  if (!out) return false;
  out << "from_id,to_id,from_utime_us,to_utime_us,matched,meas_x_m,meas_y_m,meas_theta_deg,"
         "true_x_m,true_y_m,true_theta_deg,err_x_m,err_y_m,err_theta_deg,err_xy_m,sigma_x_m,"
         "sigma_y_m,sigma_theta_deg,mahalanobis,false\n";
  // Empty fields where there is no value (unmatched, or a covariance that is not positive
  // definite), so that a reader never mistakes them for zero.
  const auto num = [](bool have, double v) { return have ? fmt::format("{:.6f}", v) : ""; };
  for (const ClosureCheck& c : ev.checks) {
    const LoopClosure& l = c.closure;
    const bool m = c.matched;
    out << fmt::format(
        "{},{},{},{},{},{:.6f},{:.6f},{:.6f},{},{},{},{},{},{},{},{:.6f},{:.6f},{:.6f},{},{}\n",
        l.from_id, l.to_id, l.from_utime, l.to_utime, m ? 1 : 0, l.T_from_to.x(), l.T_from_to.y(),
        kDegPerRad * l.T_from_to.theta(), num(m, c.T_true.x()), num(m, c.T_true.y()),
        num(m, kDegPerRad * c.T_true.theta()), num(m, c.error.x()), num(m, c.error.y()),
        num(m, kDegPerRad * c.error.z()), num(m, c.error.head<2>().norm()), c.sigma.x(),
        c.sigma.y(), kDegPerRad * c.sigma.z(),
        num(c.mahalanobis.has_value(), c.mahalanobis.value_or(0.0)), c.is_false ? 1 : 0);
  }
  return static_cast<bool>(out.flush());
}

std::optional<std::string> plot_errors(const std::string& script, const std::string& csv,
                                       const std::string& png, const std::string& title) {
  if (access(script.c_str(), R_OK) != 0) return "plot script not found: " + script;
  // Debian's interpreter first: it is the one python3-matplotlib installs into.
  int rc = -1;
  for (const char* python : {"/usr/bin/python3", "python3"}) {
    rc = run({python, script, csv, png, "--title", title});
    if (rc == 0) return std::nullopt;
    if (rc != kNoMatplotlibExitCode && rc != 127 && rc != -1) break;
  }
  if (rc == kNoMatplotlibExitCode || rc == 127 || rc == -1) {
    return "no plot: python3 with matplotlib not found (install python3-matplotlib)";
  }
  return fmt::format("no plot: {} failed with exit code {}", script, rc);
}

JsonLine& JsonLine::add(const std::string& key, const std::string& value) {
  fields_.emplace_back(key, fmt::format("\"{}\"", json_escape(value)));
  return *this;
}

JsonLine& JsonLine::add(const std::string& key, double value, int decimals) {
  if (!std::isfinite(value)) return add_null(key);
  fields_.emplace_back(key, fmt::format("{:.{}f}", value, decimals));
  return *this;
}

JsonLine& JsonLine::add(const std::string& key, std::optional<double> value, int decimals) {
  return value ? add(key, *value, decimals) : add_null(key);
}

JsonLine& JsonLine::add_int(const std::string& key, long long value) {
  fields_.emplace_back(key, std::to_string(value));
  return *this;
}

JsonLine& JsonLine::add_bool(const std::string& key, bool value) {
  fields_.emplace_back(key, value ? "true" : "false");
  return *this;
}

JsonLine& JsonLine::add_null(const std::string& key) {
  fields_.emplace_back(key, "null");
  return *this;
}

std::string JsonLine::str() const {
  std::string out = "{";
  for (std::size_t i = 0; i < fields_.size(); ++i) {
    if (i > 0) out += ", ";
    out += fmt::format("\"{}\": {}", json_escape(fields_[i].first), fields_[i].second);
  }
  return out + "}";
}

void add_evaluation(const Evaluation& ev, JsonLine& json) {
  // With nothing matched there are no errors to report, not zero errors; with too little of the
  // reference covered, none that mean anything.
  const bool report = ev.matched > 0 && !ev.refused;
  const auto figure = [&](double value) {
    return report ? std::optional<double>(value) : std::nullopt;
  };
  const auto optional = [&](std::optional<double> value) { return report ? value : std::nullopt; };
  json.add("position_rmse_m", figure(ev.position_m.rmse))
      .add("position_sd_m", figure(ev.position_m.sd))
      .add("position_max_m", figure(ev.position_m.max))
      .add("heading_rmse_deg", figure(kDegPerRad * ev.heading_rad.rmse))
      .add("heading_sd_deg", figure(kDegPerRad * ev.heading_rad.sd))
      .add("heading_max_deg", figure(kDegPerRad * ev.heading_rad.max))
      .add("rpe_1m_m", optional(ev.rpe_1m.rms_m))
      .add("rpe_10m_m", optional(ev.rpe_10m.rms_m))
      .add_int("rpe_1m_pairs", static_cast<long long>(ev.rpe_1m.pairs))
      .add_int("rpe_10m_pairs", static_cast<long long>(ev.rpe_10m.pairs))
      .add("max_jump_m", figure(ev.max_jump.step_error_m))
      .add("step_nees_median", optional(ev.step_consistency.nees_median))
      .add("step_outside_99_fraction", optional(ev.step_consistency.outside_99_fraction))
      .add_int("step_nees_steps", static_cast<long long>(ev.step_consistency.steps));
  if (ev.samples.size() >= 2) {
    const int64_t t0 = ev.samples.front().utime;
    json.add("max_jump_time_s",
             1e-6 * static_cast<double>(ev.samples[ev.max_jump.index].utime - t0), 3);
  } else {
    json.add_null("max_jump_time_s");
  }
  json.add_int("matched", static_cast<long long>(ev.matched))
      .add_int("unmatched", static_cast<long long>(ev.unmatched))
      .add_int("estimate_poses", static_cast<long long>(ev.estimate_poses))
      .add_int("reference_poses", static_cast<long long>(ev.reference_poses))
      .add_int("reference_covered", static_cast<long long>(ev.reference_covered))
      .add("reference_share", ev.reference_share, 4)
      .add_bool("refused", ev.refused)
      .add("duration_s", ev.duration_s, 3)
      .add("length_m", ev.length_m, 3)
      .add("align", align_name(ev.alignment.used))
      .add("align_x_m", ev.alignment.T_ref_est.x())
      .add("align_y_m", ev.alignment.T_ref_est.y())
      .add("align_theta_deg", kDegPerRad * ev.alignment.T_ref_est.theta());
}

void add_closures(const ClosureEvaluation& ev, JsonLine& json) {
  json.add_int("loop_closures", static_cast<long long>(ev.closures))
      .add_int("false_loop_closures", static_cast<long long>(ev.false_closures))
      .add_int("loop_closures_unmatched", static_cast<long long>(ev.unmatched))
      .add_int("loop_closures_bad_covariance", static_cast<long long>(ev.bad_covariance))
      .add("loop_closure_max_mahalanobis", ev.max_mahalanobis, 3)
      .add("loop_closure_max_error_m", ev.max_error_m)
      .add("loop_closure_rms_error_m", ev.rms_error_m);
}

void add_relations(const RelationsEvaluation& ev, JsonLine& json) {
  const bool report = !ev.refused && ev.used > 0;
  const auto figure = [&](double value) {
    return report ? std::optional<double>(value) : std::nullopt;
  };
  json.add_int("relations", static_cast<long long>(ev.relations))
      .add_int("relations_used", static_cast<long long>(ev.used))
      .add_int("relations_missing", static_cast<long long>(ev.missing))
      .add("relations_share", ev.share, 4)
      .add_bool("refused", ev.refused)
      .add("trans_mean_m", figure(ev.translation_m.mean))
      .add("trans_sd_m", figure(ev.translation_m.sd))
      .add("trans_max_m", figure(ev.translation_m.max))
      .add("trans_sq_mean_m2", figure(ev.translation_sq_m2.mean), 8)
      .add("trans_sq_sd_m2", figure(ev.translation_sq_m2.sd), 8)
      .add("rot_mean_deg", figure(ev.rotation_deg.mean))
      .add("rot_sd_deg", figure(ev.rotation_deg.sd))
      .add("rot_max_deg", figure(ev.rotation_deg.max))
      .add("rot_sq_mean_deg2", figure(ev.rotation_sq_deg2.mean))
      .add("rot_sq_sd_deg2", figure(ev.rotation_sq_deg2.sd));
}

bool write_relations_csv(const RelationsEvaluation& ev, const std::string& path) {
  std::ofstream out(path);
  if (!out) return false;
  out << "line,t1_us,t2_us,used,has_t1,has_t2,rel_x_m,rel_y_m,rel_theta_deg,est_x_m,est_y_m,"
         "est_theta_deg,trans_error_m,rot_error_deg\n";
  for (const RelationCheck& c : ev.checks) {
    const Relation& r = c.relation;
    const bool u = c.used();
    const auto num = [u](double v) { return u ? fmt::format("{:.6f}", v) : std::string(); };
    out << fmt::format("{},{},{},{},{},{},{:.6f},{:.6f},{:.6f},{},{},{},{},{}\n", r.line,
                       r.t1_utime, r.t2_utime, u ? 1 : 0, c.has_t1 ? 1 : 0, c.has_t2 ? 1 : 0,
                       r.T_1_2.x(), r.T_1_2.y(), kDegPerRad * r.T_1_2.theta(), num(c.T_est_1_2.x()),
                       num(c.T_est_1_2.y()), num(kDegPerRad * c.T_est_1_2.theta()),
                       num(c.translation_error_m), num(kDegPerRad * c.rotation_error_rad));
  }
  return static_cast<bool>(out.flush());
}

}  // namespace traverse::evaluator
