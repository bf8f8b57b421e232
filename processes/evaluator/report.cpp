#include "report.hpp"

#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>

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
         "sigma_y_m,sigma_theta_deg,mahalanobis,false,frontend_err_x_m,frontend_err_y_m,"
         "frontend_err_theta_deg,frontend_err_xy_m\n";
  // Empty fields where there is no value (unmatched, or a covariance that is not positive
  // definite), so that a reader never mistakes them for zero.
  const auto num = [](bool have, double v) { return have ? fmt::format("{:.6f}", v) : ""; };
  for (const ClosureCheck& c : ev.checks) {
    const LoopClosure& l = c.closure;
    const bool m = c.matched;
    const bool f = c.frontend_error.has_value();
    const Eigen::Vector3d fe = c.frontend_error.value_or(Eigen::Vector3d::Zero());
    out << fmt::format(
        "{},{},{},{},{},{:.6f},{:.6f},{:.6f},{},{},{},{},{},{},{},{:.6f},{:.6f},{:.6f},{},{},"
        "{},{},{},{}\n",
        l.from_id, l.to_id, l.from_utime, l.to_utime, m ? 1 : 0, l.T_from_to.x(), l.T_from_to.y(),
        kDegPerRad * l.T_from_to.theta(), num(m, c.T_true.x()), num(m, c.T_true.y()),
        num(m, kDegPerRad * c.T_true.theta()), num(m, c.error.x()), num(m, c.error.y()),
        num(m, kDegPerRad * c.error.z()), num(m, c.error.head<2>().norm()), c.sigma.x(),
        c.sigma.y(), kDegPerRad * c.sigma.z(),
        num(c.mahalanobis.has_value(), c.mahalanobis.value_or(0.0)), c.is_false ? 1 : 0,
        num(f, fe.x()), num(f, fe.y()), num(f, kDegPerRad * fe.z()), num(f, fe.head<2>().norm()));
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

void add_evaluation(const Evaluation& ev, Json& json) {
  // With nothing matched there are no errors to report, not zero errors; with too little of the
  // reference covered, none that mean anything.
  const bool report = ev.matched > 0 && !ev.refused;
  const auto figure = [&](std::optional<double> value) {
    return report ? json_fixed(value, 6) : Json();
  };
  json["position_rmse_m"] = figure(ev.position_m.rmse);
  json["position_sd_m"] = figure(ev.position_m.sd);
  json["position_max_m"] = figure(ev.position_m.max);
  json["heading_rmse_deg"] = figure(kDegPerRad * ev.heading_rad.rmse);
  json["heading_sd_deg"] = figure(kDegPerRad * ev.heading_rad.sd);
  json["heading_max_deg"] = figure(kDegPerRad * ev.heading_rad.max);
  json["rpe_1m_m"] = figure(ev.rpe_1m.rms_m);
  json["rpe_10m_m"] = figure(ev.rpe_10m.rms_m);
  json["rpe_1m_pairs"] = ev.rpe_1m.pairs;
  json["rpe_10m_pairs"] = ev.rpe_10m.pairs;
  json["max_jump_m"] = figure(ev.max_jump.step_error_m);
  json["step_nees_median"] = figure(ev.step_consistency.nees_median);
  json["step_outside_99_fraction"] = figure(ev.step_consistency.outside_99_fraction);
  json["step_nees_steps"] = ev.step_consistency.steps;
  json["max_jump_time_s"] =
      ev.samples.size() >= 2
          ? json_fixed(1e-6 * static_cast<double>(ev.samples[ev.max_jump.index].utime -
                                                  ev.samples.front().utime),
                       3)
          : Json();
  json["matched"] = ev.matched;
  json["unmatched"] = ev.unmatched;
  json["estimate_poses"] = ev.estimate_poses;
  json["reference_poses"] = ev.reference_poses;
  json["reference_covered"] = ev.reference_covered;
  json["reference_share"] = json_fixed(ev.reference_share, 4);
  json["refused"] = ev.refused;
  json["duration_s"] = json_fixed(ev.duration_s, 3);
  json["length_m"] = json_fixed(ev.length_m, 3);
  json["align"] = align_name(ev.alignment.used);
  json["align_x_m"] = json_fixed(ev.alignment.T_ref_est.x(), 6);
  json["align_y_m"] = json_fixed(ev.alignment.T_ref_est.y(), 6);
  json["align_theta_deg"] = json_fixed(kDegPerRad * ev.alignment.T_ref_est.theta(), 6);
}

void add_closures(const ClosureEvaluation& ev, Json& json) {
  json["loop_closures"] = ev.closures;
  json["false_loop_closures"] = ev.false_closures;
  json["loop_closures_unmatched"] = ev.unmatched;
  json["loop_closures_bad_covariance"] = ev.bad_covariance;
  json["loop_closure_max_mahalanobis"] = json_fixed(ev.max_mahalanobis, 3);
  json["loop_closure_max_error_m"] = json_fixed(ev.max_error_m, 6);
  json["loop_closure_rms_error_m"] = json_fixed(ev.rms_error_m, 6);
}

void add_closures_by_relations(const ClosureEvaluation& ev, double window_s, double sigmas,
                               Json& json) {
  const ClosureMedians m = medians(ev);
  const auto deg = [](std::optional<double> rad) -> std::optional<double> {
    if (!rad) return std::nullopt;
    return kDegPerRad * *rad;
  };
  json["closures"] = ev.closures;
  json["checked"] = m.checked;
  json["window_s"] = window_s;
  json["sigmas"] = sigmas;
  json["bridge_sigma_m"] = json_fixed(std::sqrt(ev.bridge_covariance(0, 0)), 4);
  json["bridge_sigma_deg"] = json_fixed(kDegPerRad * std::sqrt(ev.bridge_covariance(2, 2)), 3);
  json["median_error_m"] = json_fixed(m.error_m, 4);
  json["max_error_m"] = json_fixed(ev.max_error_m, 4);
  json["median_error_deg"] = json_fixed(deg(m.error_rad), 3);
  json["max_error_deg"] = json_fixed(deg(m.max_error_rad), 3);
  // 1.54 (the square root of chi-square 3's median) when the covariances are right.
  json["median_sigmas"] = json_fixed(m.mahalanobis, 2);
  json["max_sigmas"] = json_fixed(ev.max_mahalanobis, 2);
  json["over_sigmas"] = ev.false_closures;
  json["closures_bad_covariance"] = ev.bad_covariance;
  json["frontend_median_error_m"] = json_fixed(m.frontend_error_m, 4);
  json["frontend_median_error_deg"] = json_fixed(deg(m.frontend_error_rad), 3);
  json["closure_nearer"] = m.checked > 0 ? Json(m.closure_nearer) : Json();
}

void add_relations(const RelationsEvaluation& ev, Json& json) {
  const bool report = !ev.refused && ev.used > 0;
  const auto figure = [&](double value, int decimals = 6) {
    return report ? json_fixed(value, decimals) : Json();
  };
  json["relations"] = ev.relations;
  json["relations_used"] = ev.used;
  json["relations_missing"] = ev.missing;
  json["relations_share"] = json_fixed(ev.share, 4);
  json["refused"] = ev.refused;
  json["trans_mean_m"] = figure(ev.translation_m.mean);
  json["trans_sd_m"] = figure(ev.translation_m.sd);
  json["trans_max_m"] = figure(ev.translation_m.max);
  json["trans_sq_mean_m2"] = figure(ev.translation_sq_m2.mean, 8);
  json["trans_sq_sd_m2"] = figure(ev.translation_sq_m2.sd, 8);
  json["rot_mean_deg"] = figure(ev.rotation_deg.mean);
  json["rot_sd_deg"] = figure(ev.rotation_deg.sd);
  json["rot_max_deg"] = figure(ev.rotation_deg.max);
  json["rot_sq_mean_deg2"] = figure(ev.rotation_sq_deg2.mean);
  json["rot_sq_sd_deg2"] = figure(ev.rotation_sq_deg2.sd);
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
