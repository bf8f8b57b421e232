#include "scan_refiner.hpp"

#include <gtest/gtest.h>

#include "synthetic.hpp"

namespace traverse::backend {
namespace {

struct Scene {
  std::vector<Eigen::Vector2d> reference;  // world frame (taken at the origin)
  std::vector<Eigen::Vector2d> query;      // base frame of T_world_true
};

Scene scene(const test::synthetic::World& world, const Pose2& T_world_true, double noise_m) {
  std::mt19937 rng(11);
  ScanStoreConfig config;
  config.max_range_m = 20.0;
  const auto reduce = [&](const Pose2& T) {
    return test::to_double(reduce_scan(
        test::sweep(world, T, 20.0, rng, 1440, 0, noise_m), Pose2(),
        [](int64_t) { return Pose2(); }, config));
  };
  return {reduce(Pose2()), reduce(T_world_true)};
}

double position_error(const RefineResult& r, const Pose2& truth) {
  return (r.T_world_query.translation() - truth.translation()).norm();
}

TEST(ScanRefiner, ReachesBelowTheCorrelativeGridFromACentimetreOff) {
  const Pose2 truth(0.8, 0.5, 0.3);
  for (double noise : {0.001, 0.005}) {
    const Scene s = scene(test::synthetic::room(), truth, noise);
    for (const Pose2& start_error : {Pose2(0.015, -0.012, 0.004), Pose2(-0.02, 0.0, -0.003)}) {
      const RefineResult r = ScanRefiner({}).refine(s.reference, s.query, truth * start_error);
      ASSERT_TRUE(r.valid) << "noise " << noise;
      // A 2 cm grid leaves up to a centimetre; the refinement gets well below a millimetre.
      EXPECT_LT(position_error(r, truth), noise < 0.002 ? 0.0003 : 0.001) << "noise " << noise;
      EXPECT_LT(std::abs(wrap_angle(r.T_world_query.theta() - truth.theta())), 3e-4);
      EXPECT_GT(r.inlier_fraction, 0.5);
      EXPECT_LT(r.rms_residual_m, 3.0 * noise);
    }
  }
}

TEST(ScanRefiner, CovarianceIsWideAlongACorridorAndNarrowAcross) {
  const Pose2 truth(0.3, 0.05, 0.0);
  const Scene s = scene(test::synthetic::corridor(60.0, 2.4), truth, 0.003);
  const RefineResult r =
      ScanRefiner({}).refine(s.reference, s.query, truth * Pose2(0.01, 0.01, 0.002));
  ASSERT_TRUE(r.valid);
  // The corridor runs along x in the synthetic world; only its far ends constrain x, if at all.
  EXPECT_GT(r.covariance(0, 0), 10.0 * r.covariance(1, 1));
  EXPECT_LT(std::abs(r.T_world_query.y() - truth.y()), 0.001);
}

TEST(ScanRefiner, RefusesTooFewPointsAndAStartTooFarOff) {
  const Pose2 truth(0.8, 0.5, 0.3);
  const Scene s = scene(test::synthetic::room(), truth, 0.002);
  const Pose2 start = truth * Pose2(0.01, 0.0, 0.0);
  const ScanRefiner refiner({});
  RefineResult r = refiner.refine(s.reference, {s.query.begin(), s.query.begin() + 2}, start);
  EXPECT_FALSE(r.valid);
  r = refiner.refine({}, s.query, start);
  EXPECT_FALSE(r.valid);
  // 30 cm off: no correspondence within the 8 cm start distance leads anywhere near the truth,
  // so the result is refused and the start pose handed back.
  const Pose2 far = truth * Pose2(0.3, -0.2, 0.0);
  r = refiner.refine(s.reference, s.query, far);
  if (r.valid) {
    EXPECT_LT((r.T_world_query.translation() - far.translation()).norm(), 0.05);
  } else {
    EXPECT_EQ(r.T_world_query.translation(), far.translation());
  }
}

TEST(ScanRefiner, ConfigIsChecked) {
  RefinerConfig c;
  EXPECT_EQ(validate(c), std::nullopt);
  c.max_correspondence_m = 0.5;  // beyond the normal radius: the hash would miss neighbours
  EXPECT_TRUE(validate(c));
  c = {};
  c.covariance_scale = 0.5;
  EXPECT_TRUE(validate(c));
}

}  // namespace
}  // namespace traverse::backend
