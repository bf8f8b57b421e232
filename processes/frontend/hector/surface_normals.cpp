#include "surface_normals.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace traverse::frontend {
namespace {

// A point's neighbourhood: the points next to it along the scan, outwards on each side until one
// lies kSpanM away (a span over which range noise of millimetres tilts the fitted line by about
// a degree), at most kMaxSteps places, and none beyond max(kMinReachM, kReachPerRange x range):
// consecutive returns of a wall seen at grazing incidence lie range^2 x beam step / distance to
// the wall apart (0.9 m at 40 m for a 0.6 mrad scanner, 2 m from a wall).
constexpr double kSpanM = 0.1;
constexpr int kMaxSteps = 40;
constexpr double kMinReachM = 0.3;
constexpr double kReachPerRange = 0.1;
// Line-like: the spread across the fitted line at most this share of the spread along it
// (ratio of standard deviations).
constexpr double kMaxSpreadRatio = 1.0 / 3.0;

}  // namespace

std::vector<Eigen::Vector2d> surface_normals(const std::vector<Eigen::Vector2d>& points,
                                             const Eigen::Vector2d& origin) {
  const int n = static_cast<int>(points.size());
  std::vector<Eigen::Vector2d> normals(points.size(), Eigen::Vector2d::Zero());
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = points[i];
    const double reach = std::max(kMinReachM, kReachPerRange * (p - origin).norm());
    Eigen::Vector2d sum = p;
    Eigen::Matrix2d outer = p * p.transpose();
    int count = 1;
    for (const int step : {-1, 1}) {
      for (int j = i + step, k = 0; j >= 0 && j < n && k < kMaxSteps; j += step, ++k) {
        const double d = (points[j] - p).norm();
        if (d > reach) break;
        sum += points[j];
        outer += points[j] * points[j].transpose();
        ++count;
        if (d >= kSpanM) break;
      }
    }
    if (count < 3) continue;
    const Eigen::Vector2d mean = sum / count;
    const Eigen::Matrix2d scatter = outer / count - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
    const Eigen::Vector2d spread = eigen.eigenvalues().cwiseMax(0.0);  // ascending
    if (spread(1) <= 0.0 || spread(0) > kMaxSpreadRatio * kMaxSpreadRatio * spread(1)) continue;
    Eigen::Vector2d normal = eigen.eigenvectors().col(0);
    if (normal.dot(origin - p) < 0.0) normal = -normal;
    normals[i] = normal;
  }
  return normals;
}

}  // namespace traverse::frontend
