#include "crafted_logs.hpp"

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

namespace traverse::carmen::test {
namespace {

struct Segment {
  Eigen::Vector2d a, b;
};

std::vector<Segment> floor_plan(bool open_top) {
  std::vector<Segment> s = {
      {{0, 0}, {20, 0}}, {{20, 0}, {20, 12}}, {{0, 12}, {0, 0}},  // outer walls but the top
      {{8, 0}, {8, 7}},  {{14, 5}, {14, 12}},                     // inner walls
      {{4, 8}, {5, 8}},  {{5, 8}, {5, 9}},    {{5, 9}, {4, 9}},  {{4, 9}, {4, 8}}};  // pillar
  if (!open_top) s.push_back({{20, 12}, {0, 12}});
  return s;
}

// Distance along the ray from `o` in direction `d` to the nearest segment, or infinity.
double cast(const Eigen::Vector2d& o, const Eigen::Vector2d& d, const std::vector<Segment>& walls) {
  double best = std::numeric_limits<double>::infinity();
  for (const Segment& w : walls) {
    const Eigen::Vector2d e = w.b - w.a;
    const double den = d.x() * e.y() - d.y() * e.x();
    if (std::abs(den) < 1e-12) continue;
    const Eigen::Vector2d ao = w.a - o;
    const double t = (ao.x() * e.y() - ao.y() * e.x()) / den;
    const double u = (ao.x() * d.y() - ao.y() * d.x()) / den;
    if (t > 0 && u >= 0 && u <= 1) best = std::min(best, t);
  }
  return best;
}

// Poses every step_m along the polyline, turning on the spot at its corners.
std::vector<Pose2> along(const std::vector<Eigen::Vector2d>& corners, double step_m,
                         double long_step_m, int long_leg) {
  std::vector<Pose2> out;
  for (std::size_t leg = 0; leg + 1 < corners.size(); ++leg) {
    const Eigen::Vector2d a = corners[leg], b = corners[leg + 1];
    const double heading = std::atan2(b.y() - a.y(), b.x() - a.x());
    if (!out.empty()) {  // turn towards the new leg in steps of at most 0.35 rad
      const double turn = wrap_angle(heading - out.back().theta());
      const int n = static_cast<int>(std::ceil(std::abs(turn) / 0.35));
      for (int k = 1; k < n; ++k) out.emplace_back(a.x(), a.y(), out.back().theta() + turn / n);
    }
    const double length = (b - a).norm();
    for (double s = 0.0; s < length - 1e-9;) {
      const Eigen::Vector2d p = a + (b - a) * (s / length);
      out.emplace_back(p.x(), p.y(), heading);
      s += static_cast<int>(leg) == long_leg && s > 2.0 && s < 3.0 ? long_step_m : step_m;
    }
  }
  return out;
}

const std::vector<Eigen::Vector2d> kLoop = {{2, 2},  {2, 10},  {11, 10}, {11, 3},
                                            {17, 3}, {17, 10}, {16, 10}};

}  // namespace

std::vector<Pose2> loop_path(double step_m) { return along(kLoop, step_m, step_m, -1); }

std::vector<Pose2> loop_path_with_long_step(double step_m, double long_step_m) {
  return along(kLoop, step_m, long_step_m, 1);  // leg 1: (2, 10) to (11, 10), 9 m
}

bool write_log(const std::string& path, const CraftedLog& log) {
  std::ofstream out(path);
  out << "# crafted CARMEN log\n";
  const auto walls = floor_plan(log.open_top);
  constexpr int kBeams = 181;
  for (std::size_t i = 0; i < log.poses.size(); ++i) {
    const Pose2& p = log.poses[i];
    const std::string& ts = log.stamps.at(i);
    char pose[96];
    std::snprintf(pose, sizeof pose, "%.6f %.6f %.6f", p.x(), p.y(), p.theta());
    if (log.odometry) out << "ODOM " << pose << " 0 0 0 " << ts << " crafted " << ts << "\n";
    out << "FLASER " << kBeams;
    for (int k = 0; k < kBeams; ++k) {
      const double a = p.theta() - M_PI / 2 + M_PI * k / (kBeams - 1);
      const double r = cast(p.translation(), {std::cos(a), std::sin(a)}, walls);
      char range[16];
      std::snprintf(range, sizeof range, "%.2f", r);
      out << ' ' << (r < log.sensor_range_m ? range : log.no_return_text);
    }
    out << ' ' << pose << ' ' << pose << ' ' << ts << " crafted " << ts << "\n";
  }
  return static_cast<bool>(out.flush());
}

bool write_relations(const std::string& path, const CraftedLog& log, int gap) {
  std::ofstream out(path);
  for (std::size_t i = 0; i + gap < log.poses.size(); ++i) {
    const Pose2 d = between(log.poses[i], log.poses[i + gap]);
    char line[160];
    std::snprintf(line, sizeof line, "%s %s %.6f %.6f 0.000000 0.000000 0.000000 %.6f\n",
                  log.stamps.at(i).c_str(), log.stamps.at(i + gap).c_str(), d.x(), d.y(),
                  d.theta());
    out << line;
  }
  return static_cast<bool>(out.flush());
}

std::vector<std::string> stamps_fine(int n, double period_s) {
  std::vector<std::string> s;
  for (int k = 0; k < n; ++k) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6f", 1000.0 + k * period_s);
    s.push_back(buf);
  }
  return s;
}

std::vector<std::string> stamps_all_zero(int n) { return std::vector<std::string>(n, "0.000000"); }

std::vector<std::string> stamps_negative_then_coarse(int n, int negative) {
  std::vector<std::string> s;
  for (int k = 0; k < n; ++k) {
    if (k < negative) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.6f", -1.5 + 0.3 * k);
      s.push_back(buf);
    } else {
      s.push_back(k < n / 2 ? "1.13486e+09" : "1.13487e+09");
    }
  }
  return s;
}

std::vector<std::string> stamps_whole_seconds(int n, int per_second) {
  std::vector<std::string> s;
  for (int k = 0; k < n; ++k) s.push_back(std::to_string(1134863800 + k / per_second));
  return s;
}

}  // namespace traverse::carmen::test
