#include "annotator.hpp"

#include <algorithm>
#include <cmath>

#include "config.hpp"

namespace traverse::annotator {
namespace {

Eigen::Matrix2d translational(const Eigen::Matrix3d& covariance) {
  return covariance.topLeftCorner<2, 2>();
}

double largest_eigenvalue(const Eigen::Matrix2d& c) {
  const double mean = 0.5 * (c(0, 0) + c(1, 1));
  const double half_diff = 0.5 * (c(0, 0) - c(1, 1));
  const double off = 0.5 * (c(0, 1) + c(1, 0));
  return mean + std::sqrt(half_diff * half_diff + off * off);
}

bool changed_by(double now, double before, double fraction) {
  return std::abs(now - before) > fraction * std::abs(before);
}

}  // namespace

std::optional<std::string> validate(const AnnotatorConfig& c) {
  if (auto problem = Legend::validate(c.levels, c.limits_m, c.best_level, c.worst_level)) {
    return problem;
  }
  ConfigCheck check;
  check.require(parse_bound_method(c.bound).has_value(), "bound",
                "must be exact, chi2_max_eigen or paper, not '" + c.bound + "'");
  check.require(c.colour_by == "absolute" || c.colour_by == "local", "colour_by",
                "must be absolute or local, not '" + c.colour_by + "'");
  check.positive("covariance_scale", c.covariance_scale);
  check.not_negative("local_radius_m", c.local_radius_m);
  check.require(c.colour_by != "local" || c.local_radius_m > 0.0, "local_radius_m",
                "must be positive when colour_by is local");
  check.not_negative("republish_fraction", c.republish_fraction);
  return check.problem();
}

Annotator::Annotator(const AnnotatorConfig& config)
    : config_(config),
      method_(*parse_bound_method(config.bound)),
      legend_(config.standard, config.levels, config.limits_m, config.best_level,
              config.worst_level) {}

void Annotator::set_key_pose(int64_t id, int64_t utime, const Pose2& T_world_base,
                             const Eigen::Matrix3d& covariance) {
  keys_[id] = {utime, T_world_base, covariance};
  dirty_.push_back(id);
  ++counters_.key_poses;
}

bool Annotator::add_edge(int index, int64_t from_id, int64_t to_id, const Pose2& T_from_to,
                         const Eigen::Matrix3d& information) {
  if (index < next_edge_index_) return true;  // a repeat: already taken (or already refused)
  if (index > next_edge_index_) {
    counters_.edge_gaps += index - next_edge_index_;
    return false;
  }
  // The edge's place is taken either way: one refused edge must not hold back every later one.
  ++next_edge_index_;
  const std::optional<Eigen::Matrix3d> usable = backend::usable_information(information);
  if (from_id < 0 || to_id < 0 || from_id == to_id || !usable) {
    ++counters_.edges_rejected;
    return false;
  }
  backend::Edge e;
  e.from = static_cast<int>(from_id);
  e.to = static_cast<int>(to_id);
  e.T_from_to = T_from_to;
  e.information = *usable;
  edges_.push_back(e);
  counters_.edges = static_cast<long>(edges_.size());
  return true;
}

Annotator::LocalBounds Annotator::local_bounds(const std::vector<int64_t>& ids) {
  LocalBounds out;
  // The backend's ids are its graph's vertex indices 0..n-1; the graph needs all of them.
  const int n = static_cast<int>(keys_.size());
  if (n == 1 && keys_.begin()->first == 0) return {{{0, 0.0}}, {}};  // nothing relative
  if (n < 2 || keys_.rbegin()->first != n - 1 || edges_.empty()) return out;
  backend::PoseGraph graph;
  for (const auto& [id, key] : keys_) graph.add_vertex(id, key.T_world_base, id == 0);
  for (const backend::Edge& e : edges_) {
    if (e.from < n && e.to < n) graph.edges.push_back(e);
  }
  if (!joint_.factor(graph)) {
    ++counters_.local_failed;
    return out;
  }
  const double r2 = config_.local_radius_m * config_.local_radius_m;
  for (int64_t id : ids) {
    const int i = static_cast<int>(id);
    if (!joint_.compute_column(i)) continue;
    ++counters_.local_columns;
    const Pose2& T_i = graph.poses[i];
    // Relative covariances of the neighbours; the exact radius lies between 1.96 and 2.45 times
    // sqrt(lambda_max) (bounds.hpp), so only neighbours that can beat the best one are solved.
    std::vector<std::pair<double, Eigen::Matrix2d>> near;
    double floor_m = 0.0;
    for (int j = 0; j < n; ++j) {
      if (j == i || (graph.poses[j].translation() - T_i.translation()).squaredNorm() > r2) continue;
      const Eigen::Matrix3d S_ij = joint_.cross(j).transpose();  // E[dx_i dx_j^T]
      const Eigen::Matrix2d c =
          config_.covariance_scale * relative_position_covariance(T_i, graph.poses[j],
                                                                  joint_.marginal(i),
                                                                  joint_.marginal(j), S_ij);
      const double l1 = largest_eigenvalue(c);
      floor_m = std::max(floor_m, kNormal975 * std::sqrt(std::max(l1, 0.0)));
      near.emplace_back(l1, c);
      // The same column gives i seen from j: j's local bound has a new or moved neighbour.
      if (std::binary_search(ids.begin(), ids.end(), static_cast<int64_t>(j))) continue;
      const Eigen::Matrix2d c_j =
          config_.covariance_scale *
          relative_position_covariance(graph.poses[j], T_i, joint_.marginal(j), joint_.marginal(i),
                                       S_ij.transpose());
      double& term = out.neighbours.try_emplace(j, 0.0).first->second;
      if (std::sqrt(kChi2TwoDof95 * std::max(largest_eigenvalue(c_j), 0.0)) > term) {
        term = std::max(term, bound_95(c_j, method_));
      }
    }
    double best = 0.0;
    for (const auto& [l1, c] : near) {
      if (std::sqrt(kChi2TwoDof95 * std::max(l1, 0.0)) < floor_m) continue;
      best = std::max(best, bound_95(c, method_));
    }
    out.recomputed[id] = best;
  }
  return out;
}

bool Annotator::differs(const Annotation& a, const Annotation& b) const {
  const double f = config_.republish_fraction;
  if (a.level != b.level || changed_by(a.bound_m, b.bound_m, f)) return true;
  if ((a.local_bound_m < 0.0) != (b.local_bound_m < 0.0)) return true;
  return a.local_bound_m >= 0.0 && changed_by(a.local_bound_m, b.local_bound_m, f);
}

std::vector<Annotation> Annotator::update() {
  std::sort(dirty_.begin(), dirty_.end());
  dirty_.erase(std::unique(dirty_.begin(), dirty_.end()), dirty_.end());
  LocalBounds local;
  if (config_.local_radius_m > 0.0 && !dirty_.empty()) local = local_bounds(dirty_);
  std::vector<Annotation> out;
  last_level_changes_ = 0;
  const auto settle = [&](Annotation a) {
    // Coloured by the local bound when asked and known, else by the absolute one.
    const bool by_local = config_.colour_by == "local" && a.local_bound_m >= 0.0;
    a.level = legend_.level_of(by_local ? a.local_bound_m : a.bound_m);
    a.rgb = legend_.levels()[a.level].rgb;
    auto it = published_.find(a.id);
    if (it != published_.end() && !differs(a, it->second)) return;
    if (it != published_.end() && it->second.level != a.level) ++last_level_changes_;
    published_[a.id] = a;
    out.push_back(a);
  };
  for (int64_t id : dirty_) {
    const Key& k = keys_.at(id);
    Annotation a;
    a.id = id;
    a.utime = k.utime;
    a.T_world_base = k.T_world_base;
    a.bound_m = bound_95(config_.covariance_scale * translational(k.covariance), method_);
    if (auto it = local.recomputed.find(id); it != local.recomputed.end()) {
      a.local_bound_m = it->second;
    }
    settle(a);
  }
  // A key pose the backend did not resend but with a new or moved key pose within
  // local_radius_m: its local bound takes that neighbour too. Its other terms stay as computed
  // before: the graph has only gained information since, which never raises a covariance, so a
  // kept term is no smaller than a recomputed one (to first order) until the key pose is resent.
  for (const auto& [id, term] : local.neighbours) {
    auto it = published_.find(id);
    if (it == published_.end() || it->second.local_bound_m < 0.0) continue;
    Annotation a = it->second;
    a.local_bound_m = std::max(a.local_bound_m, term);
    settle(a);
  }
  dirty_.clear();
  counters_.annotations_changed += static_cast<long>(out.size());
  counters_.level_changes += last_level_changes_;
  return out;
}

}  // namespace traverse::annotator
