#include "point_map.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace traverse::frontend {

PointMap::PointMap(double cell_m, double point_spacing_m)
    : cell_m_(cell_m), spacing2_(point_spacing_m * point_spacing_m) {}

int PointMap::add(const std::vector<MapPoint>& points) {
  int added = 0;
  for (const MapPoint& m : points) {
    std::vector<MapPoint>& cell = cells_[key(index(m.p.x()), index(m.p.y()))];
    bool near = false;
    for (const MapPoint& o : cell) {
      if ((o.p - m.p).squaredNorm() < spacing2_) {
        near = true;
        break;
      }
    }
    if (near) continue;
    cell.push_back(m);
    ++added;
  }
  points_ += static_cast<std::size_t>(added);
  return added;
}

const MapPoint* PointMap::nearest(const Eigen::Vector2d& q, double max_distance_m) const {
  const int64_t ix = index(q.x()), iy = index(q.y());
  const MapPoint* best = nullptr;
  double best2 = max_distance_m * max_distance_m;
  for (int64_t dx = -1; dx <= 1; ++dx) {
    for (int64_t dy = -1; dy <= 1; ++dy) {
      const auto it = cells_.find(key(ix + dx, iy + dy));
      if (it == cells_.end()) continue;
      for (const MapPoint& m : it->second) {
        const double d2 = (m.p - q).squaredNorm();
        if (d2 < best2) {
          best2 = d2;
          best = &m;
        }
      }
    }
  }
  return best;
}

int64_t PointMap::drop_beyond(const Eigen::Vector2d& centre, double radius_m) {
  int64_t dropped = 0;
  for (auto it = cells_.begin(); it != cells_.end();) {
    if (it->second.empty() || (it->second.front().p - centre).norm() > radius_m) {
      points_ -= it->second.size();
      it = cells_.erase(it);
      ++dropped;
    } else {
      ++it;
    }
  }
  return dropped;
}

std::size_t PointMap::memory_bytes() const {
  return points_ * sizeof(MapPoint) +
         cells_.size() * (sizeof(Key) + sizeof(std::vector<MapPoint>) + 2 * sizeof(void*));
}

std::vector<std::optional<Eigen::Vector2d>> scan_normals(const std::vector<Eigen::Vector2d>& points,
                                                         double radius_m, double max_spread) {
  std::vector<std::optional<Eigen::Vector2d>> normals(points.size());
  const double r2 = radius_m * radius_m;
  const auto n = static_cast<long>(points.size());
  for (long i = 0; i < n; ++i) {
    // Neighbours along the scan, walking out both ways while they stay within the radius.
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    Eigen::Matrix2d outer = Eigen::Matrix2d::Zero();
    int count = 0;
    const auto take = [&](long j) {
      if (j < 0 || j >= n || (points[j] - points[i]).squaredNorm() > r2) return false;
      sum += points[j];
      outer += points[j] * points[j].transpose();
      ++count;
      return true;
    };
    take(i);
    for (long j = i - 1; take(j); --j) {
    }
    for (long j = i + 1; take(j); ++j) {
    }
    if (count < 3) continue;
    const Eigen::Vector2d mean = sum / count;
    const Eigen::Matrix2d cov = outer / count - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    const double small = std::max(0.0, eig.eigenvalues()(0)), large = eig.eigenvalues()(1);
    if (large <= 0.0 || std::sqrt(small / large) > max_spread) continue;
    normals[i] = eig.eigenvectors().col(0).normalized();
  }
  return normals;
}

}  // namespace traverse::frontend
