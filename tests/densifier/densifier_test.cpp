// Densifier: both correction modes meet the key poses, keep an exact trajectory unchanged, and on
// a platform standing nearly still the paper's uniform scaling magnifies jitter while the rigid
// correction does not. The incremental Densifier returns only new and moved segments.
#include "densifier.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace traverse::densifier {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000;
constexpr int64_t kDt = 16'750;  // [us] one frontend pose per 59.7 Hz scan

// Uniform noise in [-a, a] from a portable generator (same numbers on every platform).
double noise(std::mt19937& rng, double a) {
  return a * (2.0 * static_cast<double>(rng()) / 4294967295.0 - 1.0);
}

double max_position_error(const std::vector<StampedPose>& a, const std::vector<Pose2>& truth) {
  double e = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    e = std::max(e, (a[i].T_world_base.translation() - truth[i].translation()).norm());
  }
  return e;
}

class BothModes : public ::testing::TestWithParam<Mode> {};

TEST_P(BothModes, ExactTrajectoryIsUnchanged) {
  std::vector<StampedPose> dense;
  for (int i = 0; i <= 20; ++i) {
    dense.push_back({kT0 + i * kDt, Pose2(0.01 * i, 0.002 * i * i, 0.03 * i)});
  }
  auto out = correct_segment(dense, dense.front().T_world_base, dense.back().T_world_base,
                             GetParam(), 0.5);
  ASSERT_EQ(out.size(), dense.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_NEAR((out[i].T_world_base.translation() - dense[i].T_world_base.translation()).norm(),
                0.0, 1e-9);
    EXPECT_NEAR(wrap_angle(out[i].T_world_base.theta() - dense[i].T_world_base.theta()), 0.0, 1e-9);
    EXPECT_EQ(out[i].utime, dense[i].utime);
  }
}

TEST_P(BothModes, MeetsBothKeyPosesAndRemovesDrift) {
  // Truth: straight at 0.25 m/s with a slow turn. Dense: 1 % scale drift and a heading offset
  // growing over the segment.
  std::vector<StampedPose> dense;
  std::vector<Pose2> truth;
  for (int i = 0; i <= 20; ++i) {
    const double t = i * kDt * 1e-6;
    truth.emplace_back(0.25 * t, 0.01 * t, 0.02 * t);
    dense.push_back(
        {kT0 + i * kDt, Pose2(0.2525 * t + 0.003, 0.012 * t - 0.002, 0.02 * t + 0.001)});
  }
  auto out = correct_segment(dense, truth.front(), truth.back(), GetParam(), 0.5);
  EXPECT_NEAR((out.front().T_world_base.translation() - truth.front().translation()).norm(), 0,
              1e-12);
  EXPECT_NEAR((out.back().T_world_base.translation() - truth.back().translation()).norm(), 0,
              1e-12);
  EXPECT_NEAR(out.back().T_world_base.theta(), truth.back().theta(), 1e-12);
  // Before: 3.6 mm off at the start; after: below 0.1 mm everywhere.
  EXPECT_GT(max_position_error(dense, truth), 3e-3);
  EXPECT_LT(max_position_error(out, truth), 1e-4);
}

INSTANTIATE_TEST_SUITE_P(Densifier, BothModes, ::testing::Values(Mode::kPaper, Mode::kRigid),
                         [](const auto& info) {
                           return info.param == Mode::kPaper ? std::string("paper")
                                                             : std::string("rigid");
                         });

// Seed 000, discussion: standing nearly still, uniform scaling magnifies the frontend's jitter.
TEST(Densifier, StandingStillJitterIsMagnifiedByPaperModeOnly) {
  std::mt19937 rng(7);
  const Pose2 still(3.0, 2.0, 0.4);
  std::vector<StampedPose> dense;
  std::vector<Pose2> truth;
  for (int i = 0; i <= 20; ++i) {
    truth.push_back(still);
    dense.push_back(
        {kT0 + i * kDt, Pose2(still.x() + noise(rng, 1e-3), still.y() + noise(rng, 1e-3),
                              still.theta() + noise(rng, 2e-4))});
  }
  // The two end poses of the frontend happen to lie 0.2 mm apart; the optimiser's key poses 4 mm.
  dense.front().T_world_base = Pose2(3.0, 2.0, 0.4);
  dense.back().T_world_base = Pose2(3.0002, 2.0, 0.4);
  const Pose2 K_a(3.0, 2.0, 0.4), K_b(3.0, 2.004, 0.4);
  auto paper = correct_segment(dense, K_a, K_b, Mode::kPaper, 0.5);
  auto rigid = correct_segment(dense, K_a, K_b, Mode::kRigid, 0.5);
  const double jitter = max_position_error(dense, truth);
  EXPECT_LT(jitter, 1.5e-3);
  EXPECT_GT(max_position_error(paper, truth), 0.01);             // centimetres (x20 scale)
  EXPECT_LT(max_position_error(rigid, truth), jitter + 4.1e-3);  // jitter plus the key's offset
}

TEST(Densifier, IncrementalSegmentsAndReoptimisation) {
  Densifier d(DensifierConfig{});
  std::vector<Segment> closed;
  for (int i = 0; i < 60; ++i) {
    ASSERT_TRUE(d.add_dense(kT0 + i * kDt, Pose2(0.005 * i, 0, 0), &closed));
  }
  EXPECT_FALSE(d.add_dense(kT0, Pose2(), &closed));  // time must increase
  EXPECT_TRUE(closed.empty());
  // Three key poses at dense poses 0, 20, 40, shifted 1 cm north by the optimiser.
  std::vector<KeyPose> keys;
  for (int k = 0; k < 3; ++k) {
    keys.push_back({k, kT0 + 20 * k * kDt, Pose2(0.1 * k, 0.01, 0)});
  }
  auto segs = d.update_key_poses(keys);
  ASSERT_EQ(segs.size(), 2u);
  EXPECT_EQ(segs[0].key_id_first, 0);
  EXPECT_EQ(segs[0].key_id_last, 1);
  EXPECT_EQ(segs[0].revision, 0);
  EXPECT_EQ(segs[0].poses.size(), 21u);
  EXPECT_NEAR(d.pose_at(kT0 + 10 * kDt)->y(), 0.01, 1e-12);
  // Tail after the last key pose follows it rigidly.
  EXPECT_NEAR(d.pose_at(kT0 + 50 * kDt)->y(), 0.01, 1e-12);
  // Sending the same key again moves nothing.
  EXPECT_TRUE(d.update_key_poses({keys[2]}).empty());
  // Re-optimising key 2 moves only the segment that ends there.
  keys[2].T_world_base = Pose2(0.2, 0.02, 0);
  segs = d.update_key_poses({keys[2]});
  ASSERT_EQ(segs.size(), 1u);
  EXPECT_EQ(segs[0].key_id_first, 1);
  EXPECT_EQ(segs[0].revision, 1);
  EXPECT_EQ(d.segments_moved(), 1);
  // A key pose ahead of the dense data closes its segment when the data arrives.
  EXPECT_TRUE(d.update_key_poses({{3, kT0 + 70 * kDt, Pose2(0.35, 0.02, 0)}}).empty());
  for (int i = 60; i <= 70; ++i) d.add_dense(kT0 + i * kDt, Pose2(0.005 * i, 0, 0), &closed);
  ASSERT_EQ(closed.size(), 1u);
  EXPECT_EQ(closed[0].key_id_first, 2);
  EXPECT_EQ(closed[0].key_id_last, 3);
  EXPECT_EQ(d.corrected_trajectory().size(), 71u);
}

TEST(Densifier, MovesBelowTheThresholdWaitUntilTheEnd) {
  DensifierConfig config;
  config.republish_threshold_m = 0.001;
  Densifier d(config);
  std::vector<Segment> closed;
  for (int i = 0; i <= 40; ++i) d.add_dense(kT0 + i * kDt, Pose2(0.005 * i, 0, 0), &closed);
  std::vector<KeyPose> keys;
  for (int k = 0; k < 3; ++k) keys.push_back({k, kT0 + 20 * k * kDt, Pose2(0.1 * k, 0.0, 0)});
  ASSERT_EQ(d.update_key_poses(keys).size(), 2u);
  // 0.6 mm: below the threshold, not sent; nothing else moved, so settling sends just that.
  keys[2].T_world_base = Pose2(0.2, 0.0006, 0);
  EXPECT_TRUE(d.update_key_poses({keys[2]}).empty());
  const std::vector<Segment> settled = d.settle();
  ASSERT_EQ(settled.size(), 1u);
  EXPECT_EQ(settled[0].key_id_first, 1);
  EXPECT_NEAR(settled[0].poses.back().T_world_base.y(), 0.0006, 1e-12);
  EXPECT_TRUE(d.settle().empty());  // once settled, nothing is left to send
}

// A lone frontend pose 0.15 m off the straight path is replaced by its neighbours'
// interpolation, also inside a segment that was already closed; a sparse log's corner, where the
// neighbours are farther apart than the middle pose is off their chord, is kept.
TEST(Densifier, LoneSpikeIsReplacedAndCornersAreKept) {
  Densifier d(DensifierConfig{});
  std::vector<Segment> closed;
  ASSERT_TRUE(
      d.update_key_poses({{0, kT0, Pose2()}, {1, kT0 + 20 * kDt, Pose2(0.1, 0, 0)}}).empty());
  for (int i = 0; i <= 20; ++i) {
    d.add_dense(kT0 + i * kDt, Pose2(0.005 * i, i == 10 ? 0.15 : 0.0, 0), &closed);
  }
  EXPECT_EQ(d.spikes_replaced(), 1);
  ASSERT_FALSE(closed.empty());
  EXPECT_NEAR(closed.back().poses[10].T_world_base.y(), 0.0, 1e-12);
  EXPECT_NEAR(d.pose_at(kT0 + 10 * kDt)->y(), 0.0, 1e-12);

  // The spike is the pose a key pose sits on, in a segment closed before the next pose came.
  Densifier e(DensifierConfig{});
  closed.clear();
  for (int i = 0; i <= 10; ++i) {
    e.add_dense(kT0 + i * kDt, Pose2(0.005 * i, i == 10 ? 0.15 : 0.0, 0), &closed);
  }
  e.update_key_poses({{0, kT0, Pose2()}, {1, kT0 + 10 * kDt, Pose2(0.05, 0, 0)}});
  closed.clear();
  e.add_dense(kT0 + 11 * kDt, Pose2(0.055, 0, 0), &closed);
  EXPECT_EQ(e.spikes_replaced(), 1);
  ASSERT_EQ(closed.size(), 1u);
  EXPECT_EQ(closed[0].revision, 1);
  EXPECT_NEAR(closed[0].poses[5].T_world_base.y(), 0.0, 1e-12);  // the correction is gone

  // A sparse log turning a corner: 1 m steps, the middle pose 0.7 m off its neighbours' chord.
  Densifier f(DensifierConfig{});
  f.add_dense(kT0, Pose2(0, 0, 0), &closed);
  f.add_dense(kT0 + 1'000'000, Pose2(1, 0, 0), &closed);
  f.add_dense(kT0 + 2'000'000, Pose2(1, 1, 0), &closed);
  EXPECT_EQ(f.spikes_replaced(), 0);

  // A sparse log turning on the spot (CARMEN intel, scans 336-338): the middle pose comes 3.65 s
  // after the first and 0.18 s before the last, 6 cm off the path interpolated by time, which is
  // shorter; its neighbours lie 3.83 s apart, so nothing is known of the path between them, and
  // it is kept.
  const auto turn = [](const DensifierConfig& config, int64_t t1, int64_t t2) {
    Densifier g(config);
    std::vector<Segment> out;
    g.add_dense(kT0, Pose2(17.0311, -0.6614, 1.8256), &out);
    g.add_dense(kT0 + t1, Pose2(17.0485, -0.6493, 1.6204), &out);
    g.add_dense(kT0 + t2, Pose2(16.9879, -0.6737, 2.1498), &out);
    return g.spikes_replaced();
  };
  EXPECT_EQ(turn(DensifierConfig{}, 3'650'000, 3'830'000), 0);
  // ... and with any span too, its intervals being uneven (3.65 s and 0.18 s).
  DensifierConfig any_span;
  any_span.spike_max_span_us = 4'000'000;
  EXPECT_EQ(turn(any_span, 3'650'000, 3'830'000), 0);
  // Neighbours 0.5 s apart, as in a 4 Hz log (CARMEN freiburg-079), are no scanner's stream
  // either (a span of 0.5 s replaced real turns there); a pose 0.15 m off its neighbours' path at
  // 10 Hz is a spike.
  const auto lone = [](const DensifierConfig& config, int64_t period_us) {
    Densifier g(config);
    std::vector<Segment> out;
    g.add_dense(kT0, Pose2(0.0, 0.0, 0.0), &out);
    g.add_dense(kT0 + period_us, Pose2(0.05, 0.15, 0.0), &out);
    g.add_dense(kT0 + 2 * period_us, Pose2(0.1, 0.0, 0.0), &out);
    return g.spikes_replaced();
  };
  EXPECT_EQ(lone(DensifierConfig{}, 250'000), 0);
  DensifierConfig half_second;
  half_second.spike_max_span_us = 500'000;
  EXPECT_EQ(lone(half_second, 250'000), 1);
  EXPECT_EQ(lone(DensifierConfig{}, 100'000), 1);
  // A turn on the spot whose stamps are squeezed out of the order of the motion (Kummerle's
  // full-rate intel: 155.9, 146.3, 159.8 degrees within 50 ms, the last two microseconds apart):
  // a real pose, kept (so are poses between uneven intervals: a stream comes at a steady rate).
  const auto squeezed = [](const DensifierConfig& config) {
    Densifier g(config);
    std::vector<Segment> out;
    g.add_dense(kT0, Pose2(11.0073, 0.0, 155.9 * M_PI / 180), &out);
    g.add_dense(kT0 + 50'000, Pose2(11.0400, 0.0, 146.3 * M_PI / 180), &out);
    g.add_dense(kT0 + 50'003, Pose2(11.0129, 0.0, 159.8 * M_PI / 180), &out);
    return g.spikes_replaced();
  };
  EXPECT_EQ(squeezed(DensifierConfig{}), 0);
  // Kummerle's full-rate intel at 976054635.7 s, steady stamps: the middle pose 9.7 cm off the
  // path interpolated between neighbours 6.4 cm apart that turn 0.5 degrees, and turned 15.3
  // degrees from them. Turned that far off the interpolation, it may lie off it by the lever
  // times the angle (13 cm at turn_lever_m 0.5 m): a turn, kept (replacing it put one of the
  // benchmark's relations 15.8 degrees off). The same offset with the pose's heading on the
  // interpolation is a match that slid along what the scan cannot fix: replaced.
  const auto turned = [](double theta_middle_deg) {
    Densifier g(DensifierConfig{});
    std::vector<Segment> out;
    g.add_dense(kT0, Pose2(0.0, 0.0, 0.0), &out);
    g.add_dense(kT0 + 100'000, Pose2(0.032, 0.097, theta_middle_deg * M_PI / 180), &out);
    g.add_dense(kT0 + 200'000, Pose2(0.064, 0.0, 0.5 * M_PI / 180), &out);
    return g.spikes_replaced();
  };
  EXPECT_EQ(turned(15.3), 0);
  EXPECT_EQ(turned(0.25), 1);
  // Neighbours that turn count the turn as travel (turn_lever_m): 2.6 cm off neighbours 1.1 cm
  // apart that turn 5 degrees (4.4 cm at the lever) is no spike.
  Densifier h(DensifierConfig{});
  h.add_dense(kT0, Pose2(0.0, 0.0, 0.0), &closed);
  h.add_dense(kT0 + 100'000, Pose2(0.0055, 0.026, 2.5 * M_PI / 180), &closed);
  h.add_dense(kT0 + 200'000, Pose2(0.011, 0.0, 5.0 * M_PI / 180), &closed);
  EXPECT_EQ(h.spikes_replaced(), 0);
}

// A pose off its neighbours' path is taken for a spike only where the stream comes at its steady
// rate. Kummerle's full-rate intel at 976054570.7 s: a scan 0.2 m from its neighbours, 89 ms
// after the one before and 59 ms before the next, that the benchmark's relations put right (the
// log's stamps do not follow the motion there); after 20 scans 100 ms apart, it is kept. The
// same pose between intervals of the stream's period is replaced.
TEST(Densifier, SpikesAreLookedForOnlyWhereTheStreamIsSteady) {
  const auto run = [](int64_t in_us, int64_t out_us) {
    Densifier d(DensifierConfig{});
    std::vector<Segment> out;
    int64_t t = kT0;
    for (int i = 0; i <= 20; ++i, t += 100'000) d.add_dense(t, Pose2(0.01 * i, 0.0, 0.0), &out);
    t -= 100'000;
    d.add_dense(t + in_us, Pose2(0.21, 0.2, 0.0), &out);
    d.add_dense(t + in_us + out_us, Pose2(0.22, 0.0, 0.0), &out);
    return d.spikes_replaced();
  };
  EXPECT_EQ(run(89'000, 59'000), 0);
  EXPECT_EQ(run(100'000, 100'000), 1);
  EXPECT_EQ(run(130'000, 70'000), 1);  // within 35 % of the period (a simulated scanner's jitter)
}

}  // namespace
}  // namespace traverse::densifier
