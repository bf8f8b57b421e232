#include "relations.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "seconds_text.hpp"

namespace traverse::evaluator {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;
constexpr std::size_t kListed = 100;

std::optional<double> to_number(const std::string& tok) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (ec != std::errc() || end != tok.data() + tok.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<Relation> parse_relation(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> t;
  for (std::string tok; in >> tok;) t.push_back(tok);
  if (t.size() != 8) return std::nullopt;
  const auto t1 = seconds_text_to_utime(t[0]), t2 = seconds_text_to_utime(t[1]);
  const auto dx = to_number(t[2]), dy = to_number(t[3]), dyaw = to_number(t[7]);
  if (!t1 || !t2 || !dx || !dy || !dyaw) return std::nullopt;
  for (int i = 4; i < 7; ++i) {
    if (!to_number(t[i])) return std::nullopt;
  }
  Relation r;
  r.t1_utime = *t1;
  r.t2_utime = *t2;
  r.T_1_2 = Pose2(*dx, *dy, *dyaw);
  return r;
}

}  // namespace

RelationsFile read_relations(const std::string& path) {
  RelationsFile f;
  std::ifstream in(path);
  if (!in) {
    f.error = "cannot read " + path;
    return f;
  }
  for (std::string line; std::getline(in, line);) {
    ++f.lines;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    if (auto r = parse_relation(line)) {
      r->line = f.lines;
      f.relations.push_back(*r);
    } else {
      ++f.malformed_count;
      if (f.malformed_lines.size() < kListed) f.malformed_lines.push_back(f.lines);
    }
  }
  return f;
}

Moments moments(const std::vector<double>& values) {
  Moments m;
  if (values.empty()) return m;
  const double n = static_cast<double>(values.size());
  double sum = 0.0;
  for (double v : values) {
    sum += v;
    m.max = std::max(m.max, v);
  }
  m.mean = sum / n;
  if (values.size() < 2) return m;
  double ss = 0.0;
  for (double v : values) ss += (v - m.mean) * (v - m.mean);
  m.sd = std::sqrt(ss / (n - 1.0));
  return m;
}

RelationsEvaluation evaluate_relations(Trajectory estimate, const std::vector<Relation>& relations,
                                       const RelationsConfig& config) {
  sort_unique(estimate);
  RelationsEvaluation ev;
  ev.relations = relations.size();
  std::vector<double> trans_m, trans_sq, rot_deg, rot_sq;
  for (const Relation& r : relations) {
    RelationCheck c;
    c.relation = r;
    const StampedPose* p1 = pose_at(estimate, r.t1_utime, config.time_tolerance_us);
    const StampedPose* p2 = pose_at(estimate, r.t2_utime, config.time_tolerance_us);
    c.has_t1 = p1 != nullptr;
    c.has_t2 = p2 != nullptr;
    if (c.used()) {
      c.T_est_1_2 = between(p1->pose, p2->pose);
      c.translation_error_m = (c.T_est_1_2.translation() - r.T_1_2.translation()).norm();
      c.rotation_error_rad = std::abs(wrap_angle(c.T_est_1_2.theta() - r.T_1_2.theta()));
      const double deg = kDegPerRad * c.rotation_error_rad;
      trans_m.push_back(c.translation_error_m);
      trans_sq.push_back(c.translation_error_m * c.translation_error_m);
      rot_deg.push_back(deg);
      rot_sq.push_back(deg * deg);
      ++ev.used;
    } else {
      ++ev.missing;
    }
    ev.checks.push_back(c);
  }
  ev.share =
      ev.relations > 0 ? static_cast<double>(ev.used) / static_cast<double>(ev.relations) : 0.0;
  ev.refused = ev.relations == 0 || ev.share < config.min_share;
  ev.translation_m = moments(trans_m);
  ev.translation_sq_m2 = moments(trans_sq);
  ev.rotation_deg = moments(rot_deg);
  ev.rotation_sq_deg2 = moments(rot_sq);
  return ev;
}

}  // namespace traverse::evaluator
