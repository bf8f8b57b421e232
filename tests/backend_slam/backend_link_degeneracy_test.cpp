// The backend's links between key scans where the scans leave a direction open (backend.hpp,
// link_degeneracy_min_ratio; common/degeneracy.hpp): along a bare corridor's axis a link's
// correlative covariance claims what its search window bounds, not what the walls give, so the
// link is held there at the wheel odometry's step, or opened without odometry; in a room nothing
// is opened.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <functional>
#include <memory>
#include <random>

#include "backend.hpp"
#include "synthetic.hpp"

namespace traverse::backend {
namespace {

struct LinkDrive {
  std::vector<int64_t> utimes;
  std::vector<Pose2> truth;
  std::vector<PlanarScan> scans;
};

// Sweeps every 100 ms for `seconds` along `path`, from a scanner at the base, 5 mm range noise.
LinkDrive link_drive(const test::synthetic::World& world, const std::function<Pose2(int64_t)>& path,
                     int seconds) {
  std::mt19937 rng(5);
  LinkDrive d;
  test::synthetic::SweepSpec spec = test::full_sweep_spec();
  for (int64_t t0 = 0; t0 < 1000000LL * seconds; t0 += 100000) {
    spec.utime_first = t0;
    PlanarScan scan = test::synthetic::make_sweep(world, path, Pose2(), spec, &rng);
    d.utimes.push_back(scan.utime_last);
    d.truth.push_back(path(scan.utime_last));
    d.scans.push_back(std::move(scan));
  }
  return d;
}

// The frontend's poses are the truth (a frontend holding the corridor's axis at the odometry).
// With `odometry`, wheel odometry reads the truth shifted by 0.3 m in its own frame, every 20 ms.
std::unique_ptr<Backend> run_links(const LinkDrive& d, double min_ratio, bool odometry = false,
                                   const std::function<Pose2(int64_t)>& path = {}) {
  BackendConfig config;
  config.link_degeneracy_min_ratio = min_ratio;
  EXPECT_EQ(validate(config), std::nullopt);
  auto backend = std::make_unique<Backend>(config);
  int64_t odometry_utime = 0;
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    for (; odometry && odometry_utime <= d.utimes[k] + 100000; odometry_utime += 20000) {
      backend->add_odometry(odometry_utime, Pose2(0.3, -0.2, 0.0) * path(odometry_utime));
    }
    backend->add_scan(d.scans[k]);
    backend->add_pose(d.utimes[k], d.truth[k]);
  }
  backend->finish();
  return backend;
}

// The largest standard deviation of the link edges along the base's x axis [m].
double widest_link_along_x(const Backend& backend) {
  double widest = 0.0;
  for (const KeyEdge& e : backend.key_edges()) {
    if (e.kind != EdgeKind::kLink) continue;
    widest = std::max(widest, std::sqrt(e.information.inverse()(0, 0)));
  }
  return widest;
}

Pose2 along_corridor(int64_t utime) {
  return Pose2(-10.0 + 1e-6 * static_cast<double>(utime), 0.1, 0.0);
}

TEST(BackendLinkDegeneracy, LinksAlongABareCorridorAreOpenedAlongItsAxis) {
  const LinkDrive d = link_drive(test::synthetic::corridor(60.0, 2.4), along_corridor, 12);
  const std::unique_ptr<Backend> closed_backend = run_links(d, 0.0);
  const std::unique_ptr<Backend> opened_backend = run_links(d, 0.01);
  const Backend& closed = *closed_backend;
  const Backend& opened = *opened_backend;
  ASSERT_GT(opened.counters().links_refined, 20);
  EXPECT_EQ(closed.counters().links_opened, 0);
  EXPECT_GE(opened.counters().links_opened, opened.counters().links_refined * 9 / 10);
  // Closed, a link claims what the correlative window bounds; opened, what the refiner's own
  // information allows on top.
  EXPECT_GT(widest_link_along_x(opened), 1.5 * widest_link_along_x(closed))
      << widest_link_along_x(closed);
  // Across the corridor the links are what they were; in heading within half again (the open
  // direction carries a little heading where the scan is not symmetric about the base).
  const auto& a = closed.key_edges();
  const auto& b = opened.key_edges();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].kind != EdgeKind::kLink) continue;
    const Eigen::Matrix3d ca = a[i].information.inverse(), cb = b[i].information.inverse();
    EXPECT_NEAR(std::sqrt(cb(1, 1)), std::sqrt(ca(1, 1)), 0.2 * std::sqrt(ca(1, 1))) << i;
    EXPECT_GE(std::sqrt(cb(2, 2)), 0.99 * std::sqrt(ca(2, 2))) << i;
    EXPECT_LE(std::sqrt(cb(2, 2)), 1.5 * std::sqrt(ca(2, 2))) << i;
  }
  // The frontend's steps decide along the axis: the key poses stay on the truth.
  for (std::size_t i = 0; i < opened.key_poses().size(); ++i) {
    const int64_t utime = opened.key_poses()[i].utime;
    const Pose2 truth = along_corridor(utime);
    EXPECT_LT(std::abs(opened.key_poses()[i].T_world_base.x() - truth.x()), 0.01) << i;
  }
}

// With wheel odometry the open direction is held at the odometry's step, with its variance: the
// links say along the axis what the odometry says (its error model: 2 cm and 10 % of the step).
TEST(BackendLinkDegeneracy, WithOdometryALinkIsHeldAtItsStepAlongTheAxis) {
  const LinkDrive d = link_drive(test::synthetic::corridor(60.0, 2.4), along_corridor, 12);
  const std::unique_ptr<Backend> backend = run_links(d, 0.01, true, along_corridor);
  const BackendCounters& c = backend->counters();
  ASSERT_GT(c.links_opened, 20);
  EXPECT_EQ(c.links_held, c.links_opened);
  int checked = 0;
  for (const KeyEdge& e : backend->key_edges()) {
    if (e.kind != EdgeKind::kLink) continue;
    const double along = std::sqrt(e.information.inverse()(0, 0));
    const double step = std::abs(e.T_from_to.x());
    // The odometry's error model for the step (min_sigma_xy_m + sigma_xy_per_m * step).
    EXPECT_NEAR(along, 0.02 + 0.1 * step, 0.01) << e.from;
    EXPECT_NEAR(e.T_from_to.x(), step, 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 20);
  for (const KeyPose& k : backend->key_poses()) {
    EXPECT_LT(std::abs(k.T_world_base.x() - along_corridor(k.utime).x()), 0.01);
  }
}

TEST(BackendLinkDegeneracy, NothingIsOpenedInARoom) {
  const auto path = [](int64_t utime) {
    const double t = 1e-6 * static_cast<double>(utime);
    return Pose2(-3.0 + 0.5 * t, -0.5 + 0.1 * t, 0.2);
  };
  const std::unique_ptr<Backend> backend =
      run_links(link_drive(test::synthetic::room(), path, 10), 0.01);
  EXPECT_GT(backend->counters().links_refined, 20);
  EXPECT_EQ(backend->counters().links_opened, 0);
}

}  // namespace
}  // namespace traverse::backend
