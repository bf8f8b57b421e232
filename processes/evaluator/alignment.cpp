#include "alignment.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace traverse::evaluator {
namespace {

// [m] positions spread less than this cannot fix a rotation (a platform standing still).
constexpr double kMinSpreadM = 1e-3;

Alignment first_pose(const std::vector<Pose2>& est, const std::vector<Pose2>& ref) {
  if (est.empty()) return {Align::kFirstPose, Pose2()};
  return {Align::kFirstPose, ref.front() * est.front().inverse()};
}

}  // namespace

std::optional<Align> parse_align(const std::string& name) {
  if (name == "none") return Align::kNone;
  if (name == "first_pose") return Align::kFirstPose;
  if (name == "se2") return Align::kSe2;
  return std::nullopt;
}

std::string align_name(Align align) {
  switch (align) {
    case Align::kNone:
      return "none";
    case Align::kFirstPose:
      return "first_pose";
    case Align::kSe2:
      return "se2";
  }
  return "unknown";
}

Alignment compute_alignment(Align align, const std::vector<Pose2>& est,
                            const std::vector<Pose2>& ref) {
  if (align == Align::kNone) return {Align::kNone, Pose2()};
  if (align == Align::kFirstPose) return first_pose(est, ref);

  const auto n = static_cast<Eigen::Index>(est.size());
  Eigen::MatrixXd p_est(2, n), p_ref(2, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    p_est.col(i) = est[i].translation();
    p_ref.col(i) = ref[i].translation();
  }
  if (n < 2 ||
      (p_est.colwise() - p_est.rowwise().mean()).colwise().norm().maxCoeff() < kMinSpreadM) {
    return first_pose(est, ref);
  }
  const Eigen::MatrixXd T = Eigen::umeyama(p_est, p_ref, false);  // 3x3 homogeneous
  return {Align::kSe2, Pose2(T(0, 2), T(1, 2), std::atan2(T(1, 0), T(0, 0)))};
}

}  // namespace traverse::evaluator
