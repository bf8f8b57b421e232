// The mapper's screen preview: one point per cell of its grid, in the base frame at the profile's
// time, from the mapper's own placement, sent once per profile (a loop closure moves no preview
// point: the viewer moves the profile's pose), in messages of a bounded number of points.
#include "preview.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <random>

#include "mapper.hpp"
#include "preview_corridor.hpp"
#include "preview_resend.hpp"

namespace traverse::mapper {
namespace {

constexpr int64_t kT0 = kCorridorT0;

TEST(CloudPreview, KeepsOnePointPerCellInTheBaseFrame) {
  CloudPreview preview({.channel = "CLOUD_PREVIEW", .cell_m = 0.1, .max_points_per_message = 3});
  const Pose2 T(10.0, 5.0, std::numbers::pi / 2);  // base at (10, 5), facing +y
  // Two points in one cell, one in another; p_world = T * (1, 0) = (10, 6).
  preview.add(kT0, T, {{10.0f, 6.0f, 1.5f}, {10.01f, 6.02f, 1.51f}, {10.5f, 6.0f, 0.2f}});
  EXPECT_EQ(preview.points(), 2);
  // A later profile over the same cells adds nothing; one new cell adds one point.
  preview.add(kT0 + 1, T, {{10.02f, 6.01f, 1.52f}, {12.0f, 6.0f, 0.0f}});
  EXPECT_EQ(preview.points(), 3);
  EXPECT_EQ(preview.cells(), 3);
  const auto groups = preview.take();
  ASSERT_EQ(groups.size(), 1u);
  ASSERT_EQ(groups[0].size(), 2u);
  const PreviewProfile& first = groups[0][0];
  EXPECT_EQ(first.utime, kT0);
  ASSERT_EQ(first.p_base_mm.size(), 2u);
  EXPECT_EQ(first.p_base_mm[0], (std::array<int16_t, 3>{1000, 0, 1500}));    // 1 m ahead
  EXPECT_EQ(first.p_base_mm[1], (std::array<int16_t, 3>{1000, -500, 200}));  // and 0.5 m right
  EXPECT_TRUE(preview.take().empty());                                       // each once
}

TEST(CloudPreview, SplitsLongProfilesAcrossMessages) {
  CloudPreview preview({.channel = "CLOUD_PREVIEW", .cell_m = 0.1, .max_points_per_message = 4});
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 10; ++i) pts.emplace_back(0.2f * i, 0.0f, 0.0f);
  preview.add(kT0, Pose2(), pts);
  const auto groups = preview.take();
  ASSERT_EQ(groups.size(), 3u);  // 4 + 4 + 2 points, every part of the same profile
  std::size_t n = 0;
  for (const auto& g : groups) {
    for (const auto& p : g) {
      EXPECT_EQ(p.utime, kT0);
      n += p.p_base_mm.size();
    }
  }
  EXPECT_EQ(n, 10u);
}

TEST(CloudPreview, ComesFromTheMappersPlacementOncePerProfile) {
  MapperConfig config;
  config.footprint = {-0.1, 0.1, -0.1, 0.1, 0.02, 0.5};
  Eigen::Isometry3d T_base_laser = Eigen::Isometry3d::Identity();
  T_base_laser.translation() = Eigen::Vector3d(0.4, 0.0, 1.0);
  Mapper mapper(config, T_base_laser);
  int calls = 0;
  Pose2 pose_seen;
  std::vector<Eigen::Vector3f> points_seen;
  mapper.on_first_placement([&](int64_t, const Pose2& T, const std::vector<Eigen::Vector3f>& p) {
    ++calls;
    pose_seen = T;
    points_seen = p;
  });
  Profile p;
  p.utime_first = kT0 + 10'000;
  p.utime_last = kT0 + 20'000;
  p.angle_first = 0.0f;
  p.angle_step = 0.01f;
  p.ranges.assign(11, 2.0f);
  ASSERT_TRUE(mapper.add_profile(p));
  EXPECT_EQ(calls, 0);  // no trajectory yet
  auto segment = [](double y) {
    TrajectorySegment s;
    s.key_id_first = 0;
    for (int i = 0; i <= 10; ++i) {
      s.utimes.push_back(kT0 + i * 5'000);
      s.T_world_base.emplace_back(0.0, y, 0.0);
    }
    return s;
  };
  ASSERT_TRUE(mapper.set_segment(segment(0.0)));
  ASSERT_EQ(calls, 1);
  EXPECT_NEAR(pose_seen.y(), 0.0, 1e-12);
  ASSERT_EQ(points_seen.size(), 11u);
  EXPECT_NEAR(points_seen[0].x(), 2.4f, 1e-5);  // 2 m along the beam from the scanner at 0.4 m
  EXPECT_NEAR(points_seen[0].z(), 1.0f, 1e-5);
  // A loop closure moves the segment: the points move in the map, the preview is not called.
  ASSERT_TRUE(mapper.set_segment(segment(0.3)));
  mapper.apply_moves();
  EXPECT_EQ(calls, 1);
}

// What a late viewer is sent after a long run: bounded by the cap however long the run, and a
// picture of the whole route, the start included (the earliest point of each coarse cell is kept).
TEST(PreviewResend, StaysUnderItsCapAndCoversTheWholeRoute) {
  constexpr int64_t kCap = 256 << 10;
  PreviewResend resend(0.05, kCap);
  int64_t max_bytes[1] = {0};
  const int64_t sent = drive_corridor(0.0, 200.0, resend, max_bytes);
  // Everything sent live would have been kept before: 6 bytes a point.
  ASSERT_GT(sent * 6, 10 * kCap);
  EXPECT_LE(max_bytes[0], kCap);
  EXPECT_LE(resend.bytes(), kCap);
  EXPECT_GT(resend.counters().compactions, 0);
  EXPECT_EQ(resend.counters().points_compacted, sent - resend.points());
  EXPECT_GT(resend.cell_m(), 0.05);
  RecordProperty("points_sent_live", std::to_string(sent));
  RecordProperty("points_kept", std::to_string(resend.points()));
  RecordProperty("cell_m", std::to_string(resend.cell_m()));

  resend.answer();
  std::vector<int> per_metre(201, 0);
  int64_t answered = 0, last_utime = 0;
  bool first_profile = false;
  while (resend.resending()) {
    const std::vector<PreviewProfile> part = resend.next(9000);
    std::size_t n = 0;
    for (const PreviewProfile& p : part) {
      EXPECT_GE(p.utime, last_utime);  // in time order, a long profile continued
      last_utime = p.utime;
      first_profile |= p.utime == kT0;
      n += p.p_base_mm.size();
      for (const auto& q : p.p_base_mm) {
        const double x = p.T_world_base.x() + q[0] * 1e-3;
        ++per_metre[std::clamp(static_cast<int>(x), 0, 200)];
      }
    }
    ASSERT_GT(n, 0u);
    EXPECT_LE(n, 9000u);
    answered += static_cast<int64_t>(n);
  }
  EXPECT_EQ(answered, resend.points());
  EXPECT_TRUE(first_profile);  // the very start of the route
  for (int m = 0; m < 200; ++m) EXPECT_GT(per_metre[m], 0) << "no point between " << m << " m";
}

// Live, the passes run on a thread of their own while the route goes on: what arrives meanwhile is
// kept apart and merged after the thinned store, so the answer still covers the whole route from
// its first profile, in time order, and once the passes are done the store is under its cap.
TEST(PreviewResend, InTheBackgroundKeepsTheWholeRouteToo) {
  constexpr int64_t kCap = 256 << 10;
  PreviewResend resend(0.05, kCap, true);
  int64_t max_bytes[1] = {0};
  const int64_t sent = drive_corridor(0.0, 200.0, resend, max_bytes);
  resend.wait();
  EXPECT_FALSE(resend.thinning());
  EXPECT_GT(resend.counters().compactions, 0);
  EXPECT_LE(resend.bytes(), kCap);
  EXPECT_EQ(resend.counters().points_compacted, sent - resend.points());
  EXPECT_GT(resend.cell_m(), 0.05);
  resend.answer();
  std::vector<int> per_metre(201, 0);
  int64_t answered = 0, last_utime = 0;
  bool first_profile = false;
  while (resend.resending()) {
    for (const PreviewProfile& p : resend.next(9000)) {
      EXPECT_GE(p.utime, last_utime);  // in time order, what came during a pass after the rest
      last_utime = p.utime;
      first_profile |= p.utime == kT0;
      answered += static_cast<int64_t>(p.p_base_mm.size());
      for (const auto& q : p.p_base_mm) {
        ++per_metre[std::clamp(static_cast<int>(p.T_world_base.x() + q[0] * 1e-3), 0, 200)];
      }
    }
  }
  EXPECT_EQ(answered, resend.points());
  EXPECT_TRUE(first_profile);
  for (int m = 0; m < 200; ++m) EXPECT_GT(per_metre[m], 0) << "no point between " << m << " m";
}

// The answer is paced out over seconds while the route goes on: a thinning pass meanwhile leaves
// it going on in time order, under the cap, to the end.
TEST(PreviewResend, AnAnswerUnderWayGoesOnThroughACompaction) {
  PreviewResend resend(0.05, 64 << 10);
  int64_t max_bytes[1] = {0};
  drive_corridor(0.0, 20.0, resend, max_bytes);
  const int64_t compactions = resend.counters().compactions;
  resend.answer();
  std::vector<PreviewProfile> got = resend.next(50);
  ASSERT_FALSE(got.empty());
  // More route arrives while the answer is paced out: the kept points are thinned again.
  drive_corridor(20.05, 80.0, resend, max_bytes);
  EXPECT_GT(resend.counters().compactions, compactions);
  EXPECT_LE(max_bytes[0], 64 << 10);
  int64_t last_utime = got.back().utime;
  std::size_t answered = 0;
  while (resend.resending()) {
    for (const PreviewProfile& p : resend.next(50)) {
      EXPECT_GE(p.utime, last_utime);
      last_utime = p.utime;
      answered += p.p_base_mm.size();
    }
  }
  EXPECT_GT(answered, 0u);
}

// A pass that ends while the answer is inside a profile sends that profile again from its first
// point: its points moved, and what the pass kept of the rest of it is not lost.
TEST(PreviewResend, APassInsideAProfileLosesNoneOfItsKeptPoints) {
  PreviewResend resend(0.05, 2048);
  PreviewProfile a{kT0, {}, Pose2()};
  for (int16_t i = 0; i < 100; ++i) a.p_base_mm.push_back({static_cast<int16_t>(300 * i), 0, 0});
  resend.add(a);  // 696 bytes
  resend.answer();
  std::vector<std::array<int16_t, 3>> got;
  for (const PreviewProfile& p : resend.next(10)) {
    got.insert(got.end(), p.p_base_mm.begin(), p.p_base_mm.end());
  }
  // Later profiles in a's cells, until the store passes its cap: thinned away (a's are earlier).
  for (int j = 1; j <= 7; ++j) {
    resend.add({kT0 + j * 1000, {a.p_base_mm.begin(), a.p_base_mm.begin() + 20}, Pose2()});
  }
  ASSERT_EQ(resend.counters().compactions, 1);
  EXPECT_EQ(resend.profiles(), 1u);
  while (resend.resending()) {
    for (const PreviewProfile& p : resend.next(10)) {
      got.insert(got.end(), p.p_base_mm.begin(), p.p_base_mm.end());
    }
  }
  int missed = 0;
  for (const auto& p : a.p_base_mm) missed += std::find(got.begin(), got.end(), p) == got.end();
  EXPECT_EQ(missed, 0);
}

// A thinning pass coarsens the cells from their indices: the same cell as preview_cell() at twice
// the edge, for points on both sides of the origin and on cell boundaries.
TEST(PreviewCell, DoubledFromItsIndicesIsTheCellAtTwiceTheEdge) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-900.0, 900.0);
  for (double cell_m : {0.05, 0.1, 0.2, 0.35, 1.6, 12.8}) {
    for (int i = 0; i < 20000; ++i) {
      double x = coordinate(rng), y = coordinate(rng), z = coordinate(rng) / 100.0;
      if (i % 4 == 0) x = cell_m * std::round(x / cell_m);  // on a boundary
      const auto fine = preview_cell(x, y, z, cell_m);
      const auto coarse = preview_cell(x, y, z, 2.0 * cell_m);
      ASSERT_TRUE(fine && coarse);
      ASSERT_EQ(preview_cell_doubled(*fine), *coarse) << x << " " << y << " " << z << " " << cell_m;
    }
  }
}

// Right after each thinning pass the store holds, for every cell of its grid that any point sent
// fell in, exactly the earliest of them.
TEST(PreviewResend, AfterAPassEachCellHoldsItsEarliestPoint) {
  PreviewResend resend(0.05, 16 << 10);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> horizontal(-3000, 3000), vertical(0, 2500);  // [mm]
  std::vector<PreviewProfile> sent;
  using Point = std::pair<int64_t, std::array<int16_t, 3>>;  // utime [us], base frame [mm]
  int passes_checked = 0;
  for (int i = 0; i < 400; ++i) {
    // Poses exact in float (as the store keeps them) and no turn: cells computed here as there.
    PreviewProfile p{kT0 + i * 33'333, {}, Pose2(0.25 * (i % 40), 0.0, 0.0)};
    for (int j = 0; j < 60; ++j) {
      p.p_base_mm.push_back({static_cast<int16_t>(horizontal(rng)),
                             static_cast<int16_t>(horizontal(rng)),
                             static_cast<int16_t>(vertical(rng))});
    }
    const int64_t passes = resend.counters().compactions;
    resend.add(p);
    sent.push_back(p);
    if (resend.counters().compactions == passes) continue;
    ++passes_checked;
    const auto cell_of = [&](const PreviewProfile& profile, const std::array<int16_t, 3>& q) {
      return preview_cell(profile.T_world_base.x() + q[0] * 1e-3, q[1] * 1e-3, q[2] * 1e-3,
                          resend.cell_m());
    };
    std::map<uint64_t, Point> earliest, kept;
    for (const PreviewProfile& s : sent) {
      for (const auto& q : s.p_base_mm) earliest.try_emplace(cell_of(s, q).value(), s.utime, q);
    }
    resend.answer();
    while (resend.resending()) {
      for (const PreviewProfile& k : resend.next(1000)) {
        for (const auto& q : k.p_base_mm) {
          EXPECT_TRUE(kept.try_emplace(cell_of(k, q).value(), k.utime, q).second);
        }
      }
    }
    EXPECT_EQ(kept, earliest) << "after pass " << resend.counters().compactions;
  }
  EXPECT_GE(passes_checked, 3);
  EXPECT_GT(resend.cell_m(), 0.2);
}

}  // namespace
}  // namespace traverse::mapper
