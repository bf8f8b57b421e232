#include "products.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <string>

#include "annotator.hpp"
#include "bounds.hpp"
#include "channels.hpp"
#include "lcm_log.hpp"
#include "levels.hpp"
#include "traverse/dense_segments_t.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::exporter {

namespace {

template <class T>
bool decode(const std::vector<uint8_t>& data, T& msg) {
  const int size = static_cast<int>(data.size());
  return msg.decode(data.data(), 0, size) == size;
}

Eigen::Matrix3d row_major(const double* c) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = c[i];
  return m;
}

}  // namespace

RunEstimate read_run(const std::string& log_path, const std::string& reference_channel) {
  RunEstimate run;
  LogReader reader(log_path);
  while (auto ev = reader.next()) {
    ++run.events;
    if (ev->channel == channels::kKeyPoses) {
      key_poses_t m;
      if (!decode(ev->data, m)) {
        ++run.decode_failures;
        continue;
      }
      for (const key_pose_t& k : m.poses) {
        run.key_poses[k.id] = {k.utime, Pose2(k.x, k.y, k.theta), row_major(k.covariance)};
      }
    } else if (ev->channel == channels::kDenseSegments) {
      dense_segments_t m;
      if (!decode(ev->data, m)) {
        ++run.decode_failures;
        continue;
      }
      for (const dense_segment_t& s : m.segments) {
        auto it = run.segments.find(s.key_id_first);
        if (it != run.segments.end() && it->second.revision > s.revision) continue;
        Segment seg{s.key_id_first, s.key_id_last, s.revision, s.pose_utime, {}};
        for (int i = 0; i < s.n_poses; ++i) seg.poses.emplace_back(s.x[i], s.y[i], s.theta[i]);
        run.segments[s.key_id_first] = std::move(seg);
      }
    } else if (ev->channel == reference_channel) {
      pose2d_t m;
      if (!decode(ev->data, m)) {
        ++run.decode_failures;
        continue;
      }
      run.ground_truth.emplace_back(m.utime, Pose2(m.x, m.y, m.theta));
    }
  }
  run.damaged_records = static_cast<int64_t>(reader.damage().size());
  std::sort(run.ground_truth.begin(), run.ground_truth.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  return run;
}

std::vector<DensePose> dense_trajectory(const RunEstimate& run) {
  std::vector<DensePose> out;
  auto covariance_of = [&run](int64_t id) {
    auto it = run.key_poses.find(id);
    return it == run.key_poses.end() ? Eigen::Matrix3d::Zero().eval() : it->second.covariance;
  };
  for (const auto& [first, seg] : run.segments) {
    if (seg.poses.empty()) continue;
    const Eigen::Matrix3d c0 = covariance_of(seg.key_id_first);
    const Eigen::Matrix3d c1 = covariance_of(seg.key_id_last);
    const double t0 = static_cast<double>(seg.utime.front());
    const double span = static_cast<double>(seg.utime.back()) - t0;
    for (std::size_t i = 0; i < seg.poses.size(); ++i) {
      if (!out.empty() && seg.utime[i] <= out.back().utime) continue;  // shared end pose
      const double s = span > 0 ? (static_cast<double>(seg.utime[i]) - t0) / span : 0.0;
      out.push_back(
          {seg.utime[i], seg.poses[i], (1 - s) * c0 + s * c1, seg.key_id_first, seg.key_id_last});
    }
  }
  return out;
}

std::optional<Pose2> world_from_map(const RunEstimate& run, const std::vector<DensePose>& dense) {
  if (dense.empty() || run.ground_truth.size() < 2) return std::nullopt;
  const int64_t t = dense.front().utime;
  const auto& gt = run.ground_truth;
  auto after = std::lower_bound(gt.begin(), gt.end(), t,
                                [](const auto& a, int64_t u) { return a.first < u; });
  if (after == gt.end() || (after == gt.begin() && after->first != t)) return std::nullopt;
  Pose2 T_world_base = after->second;
  if (after->first != t) {
    const auto before = std::prev(after);
    const double s =
        static_cast<double>(t - before->first) / static_cast<double>(after->first - before->first);
    T_world_base = interpolate(before->second, after->second, s);
  }
  return T_world_base * dense.front().pose.inverse();
}

DensePose transformed(const DensePose& p, const Pose2& T_out_map) {
  DensePose q = p;
  q.pose = T_out_map * p.pose;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  R.topLeftCorner<2, 2>() = T_out_map.rotation();
  q.covariance = R * p.covariance * R.transpose();
  return q;
}

double bound95_m(const Eigen::Matrix3d& covariance) {
  // The lower triangle (a covariance rotated into another frame may be asymmetric by rounding).
  const Eigen::Matrix2d c = covariance.topLeftCorner<2, 2>().selfadjointView<Eigen::Lower>();
  if (!c.allFinite()) return std::numeric_limits<double>::infinity();
  return annotator::bound_95(c, annotator::BoundMethod::kPaper);
}

int loa_level(double bound) {
  // The annotator's default legend is the USIBD LOA: levels named LOA50 (best) .. LOA10.
  static const annotator::Legend legend = [] {
    const annotator::AnnotatorConfig c;
    return annotator::Legend(c.standard, c.levels, c.limits_m, c.best_level, c.worst_level);
  }();
  return std::stoi(legend.levels()[legend.level_of(bound)].name.substr(3));
}

std::array<uint8_t, 3> level_colour(int level, int top_level, int bottom_level) {
  if (level >= top_level) return {0, 200, 0};
  if (level < bottom_level) return {220, 0, 0};
  // Between: yellow at the level just below the top, orange at the bottom level.
  const int steps = std::max(1, (top_level - bottom_level) / 10);
  const double s = static_cast<double>(top_level - 10 - level) / 10.0 / std::max(1, steps - 1);
  const double green = 220.0 - std::clamp(s, 0.0, 1.0) * 100.0;  // 220 yellow .. 120 orange
  return {230, static_cast<uint8_t>(green), 0};
}

bool write_tum(const std::string& path, const std::vector<DensePose>& poses,
               const std::string& frame) {
  std::ofstream f(path);
  f << "# Traverse trajectory, TUM format: timestamp [s since the Unix epoch] tx ty tz [m] "
       "qx qy qz qw, T_"
    << frame << "_base, frame " << frame << "\n";
  f << std::fixed;
  for (const DensePose& p : poses) {
    const double h = 0.5 * p.pose.theta();
    f << std::setprecision(6) << static_cast<double>(p.utime) * 1e-6 << ' ' << std::setprecision(6)
      << p.pose.x() << ' ' << p.pose.y() << " 0.000000 0 0 " << std::setprecision(9) << std::sin(h)
      << ' ' << std::cos(h) << '\n';
  }
  return static_cast<bool>(f);
}

bool write_trajectory_csv(const std::string& path, const std::vector<DensePose>& poses,
                          const std::string& frame) {
  std::ofstream f(path);
  f << "time_s,x_m,y_m,theta_rad,frame,cov_xx_m2,cov_xy_m2,cov_xtheta_m_rad,cov_yx_m2,cov_yy_m2,"
       "cov_ytheta_m_rad,cov_thetax_m_rad,cov_thetay_m_rad,cov_thetatheta_rad2,bound95_m,"
       "loa_level,key_id_first,key_id_last\n";
  for (const DensePose& p : poses) {
    f << std::fixed << std::setprecision(6) << static_cast<double>(p.utime) * 1e-6 << ','
      << p.pose.x() << ',' << p.pose.y() << ',' << std::setprecision(9) << p.pose.theta() << ','
      << frame << std::scientific << std::setprecision(6);
    for (int i = 0; i < 9; ++i) f << ',' << p.covariance(i / 3, i % 3);
    const double b = bound95_m(p.covariance);
    f << std::fixed << std::setprecision(6) << ',' << b << ',' << loa_level(b) << ','
      << p.key_id_first << ',' << p.key_id_last << '\n';
  }
  return static_cast<bool>(f);
}

}  // namespace traverse::exporter
