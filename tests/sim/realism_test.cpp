// The scan statistics of scripts/sim-realism.sh on scans whose answer is known.
#include "realism.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "rng.hpp"

namespace traverse::sim {
namespace {

// Ranges of a wall 5 m ahead (perpendicular to the middle beam) with white noise, 1 deg steps.
std::vector<float> wall_scan(Rng& rng, double sigma, double max_angle = 1.2, int n = 181) {
  std::vector<float> r(n);
  for (int i = 0; i < n; ++i) {
    const double a = (i - n / 2) * std::numbers::pi / 180.0;
    r[i] =
        static_cast<float>(std::abs(a) < max_angle ? 5.0 / std::cos(a) + rng.normal(sigma) : 0.0);
  }
  return r;
}

TEST(Realism, ResidualSigmaOfANoisyWallIsItsNoise) {
  Rng rng(1);
  ScanStats stats;
  const RealismConfig c;
  for (int k = 0; k < 2000; ++k) stats.add(wall_scan(rng, 0.01, 0.15), -M_PI / 2, M_PI / 180, c);
  const RealismSummary s = summarize(stats);
  // A point against the line through its four neighbours: sigma x sqrt(1 + 1/4) at the line's
  // centre (the noise along the beam, nearly normal to the wall within 0.15 rad).
  EXPECT_NEAR(s.sigma_m, 0.01 * std::sqrt(1.25), 0.0006);
  EXPECT_NEAR(s.tail_fraction, 0.0027, 0.0015);  // Gaussian: 0.27 % beyond 3 sigma
  EXPECT_EQ(s.jumps_per_scan, 0.0);
  EXPECT_EQ(s.outlier_fraction, 0.0);
  EXPECT_NEAR(s.return_fraction, 17.0 / 181.0, 1e-9);  // |a| < 0.15 rad: 17 of 181 beams
  // Out to 1.2 rad the wall is seen ever more obliquely: long steps, but no depth jump.
  ScanStats wide;
  for (int k = 0; k < 20; ++k) wide.add(wall_scan(rng, 0.0), -M_PI / 2, M_PI / 180, c);
  EXPECT_EQ(wide.jumps, 0);
  EXPECT_EQ(wide.mixed + wide.outliers, 0);
}

TEST(Realism, AMixedPixelAndAnOutlierAreCounted) {
  Rng rng(2);
  std::vector<float> r = wall_scan(rng, 0.0);
  for (int i = 100; i < 110; ++i) r[i] = 2.0f;  // a box in front: two depth jumps
  r[110] = 3.5f;                                // a point floating between box and wall
  r[60] = 1.0f;                                 // a lone return off both neighbours
  ScanStats stats;
  stats.add(r, -M_PI / 2, M_PI / 180, RealismConfig{});
  const RealismSummary s = summarize(stats);
  // Jumps: the box's clean edge, both halves of the edge the mixed pixel splits, and both sides
  // of the lone return.
  EXPECT_EQ(stats.jumps, 5);
  EXPECT_EQ(stats.mixed, 1);
  EXPECT_EQ(stats.outliers, 1);  // the lone return (a spike)
  EXPECT_NEAR(s.mixed_per_jump, 0.2, 1e-12);
  EXPECT_NEAR(s.outlier_fraction, 2.0 / 137.0, 1e-12);
}

}  // namespace
}  // namespace traverse::sim
