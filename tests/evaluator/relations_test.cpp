// Scoring by relations (Kümmerle et al. 2009): a trajectory perturbed by known amounts gives
// exactly those amounts back; the frame the estimate is in does not matter; a relation is matched
// to the pose at its scan's exact stamp or is missing, never interpolated; too few relations used
// means no figures.
#include "relations.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

namespace traverse::evaluator {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

// A random walk of `n` poses 0.2 s apart (the truth), stamped like intel's scans.
Trajectory truth(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> step(0.0, 0.5), side(-0.05, 0.05), turn(-0.3, 0.3);
  Trajectory t;
  Pose2 p(3.0, -1.0, 0.5);
  for (int i = 0; i < n; ++i) {
    t.push_back({976'052'857'337'530 + i * 200'000, p});
    p = p * Pose2(step(rng), side(rng), turn(rng));
  }
  return t;
}

// The relation between poses i and j of the truth.
Relation relation(const Trajectory& t, std::size_t i, std::size_t j) {
  return Relation{t[i].utime, t[j].utime, between(t[i].pose, t[j].pose), 0};
}

TEST(Relations, PerturbedByAKnownAmountGivesThatAmountBack) {
  std::mt19937 rng(1);
  const Trajectory t = truth(200, rng);
  std::vector<Relation> relations;
  for (std::size_t i = 0; i + 1 < t.size(); ++i) relations.push_back(relation(t, i, i + 1));
  // Each step of the estimate is the true step followed by a known error, alternating between
  // (0.01 m, 0.5 deg) and (0.03 m, 1.5 deg) in a direction that turns with the step.
  Trajectory est = {t[0]};
  std::vector<double> trans, rot_deg;
  for (std::size_t i = 0; i + 1 < t.size(); ++i) {
    const double e_m = i % 2 ? 0.03 : 0.01, e_deg = i % 2 ? 1.5 : -0.5;
    const double dir = 0.7 * static_cast<double>(i);
    const Pose2 error(e_m * std::cos(dir), e_m * std::sin(dir), e_deg / kDegPerRad);
    est.push_back({t[i + 1].utime, est.back().pose * between(t[i].pose, t[i + 1].pose) * error});
    trans.push_back(e_m);
    rot_deg.push_back(std::abs(e_deg));
  }
  const RelationsEvaluation ev = evaluate_relations(est, relations, {});
  EXPECT_EQ(ev.relations, 199u);
  EXPECT_EQ(ev.used, 199u);
  EXPECT_EQ(ev.missing, 0u);
  EXPECT_FALSE(ev.refused);
  // 100 steps of the first kind and 99 of the second.
  const double n = 199, mean_m = (100 * 0.01 + 99 * 0.03) / n;
  const double sd_m =
      std::sqrt((100 * std::pow(0.01 - mean_m, 2) + 99 * std::pow(0.03 - mean_m, 2)) / (n - 1));
  EXPECT_NEAR(ev.translation_m.mean, mean_m, 1e-12);
  EXPECT_NEAR(ev.translation_m.sd, sd_m, 1e-12);
  EXPECT_NEAR(ev.translation_m.max, 0.03, 1e-12);
  const double mean_deg = (100 * 0.5 + 99 * 1.5) / n;
  EXPECT_NEAR(ev.rotation_deg.mean, mean_deg, 1e-9);
  EXPECT_NEAR(ev.rotation_deg.max, 1.5, 1e-9);
  EXPECT_NEAR(ev.translation_sq_m2.mean, (100 * 1e-4 + 99 * 9e-4) / n, 1e-12);
  EXPECT_NEAR(ev.rotation_sq_deg2.mean, (100 * 0.25 + 99 * 2.25) / n, 1e-9);
  const Moments m = moments(trans);
  EXPECT_NEAR(m.sd, sd_m, 1e-15);
  EXPECT_NEAR(moments(rot_deg).sd, ev.rotation_deg.sd, 1e-9);
}

TEST(Relations, TheEstimatesFrameDoesNotMatter) {
  std::mt19937 rng(2);
  const Trajectory t = truth(100, rng);
  std::vector<Relation> relations;
  for (std::size_t i = 0; i + 7 < t.size(); i += 3) relations.push_back(relation(t, i, i + 7));
  Trajectory est = t;
  const Pose2 T_other_world(-40.0, 12.0, 2.5);
  for (StampedPose& p : est) p.pose = T_other_world * p.pose;
  const RelationsEvaluation ev = evaluate_relations(est, relations, {});
  EXPECT_EQ(ev.used, relations.size());
  EXPECT_LT(ev.translation_m.max, 1e-12);
  EXPECT_LT(ev.rotation_deg.max, 1e-9);
}

TEST(Relations, ARelationIsMatchedAtItsScansStampOrMissing) {
  std::mt19937 rng(3);
  Trajectory t = truth(10, rng);
  // Two scans 6 us apart (intel has such pairs): the relation names the second.
  t.insert(t.begin() + 5, {t[5].utime - 6, Pose2(100.0, 100.0, 0.0)});
  const std::vector<Relation> relations = {relation(t, 2, 6), relation(t, 4, 8)};
  Trajectory est = t;
  EXPECT_LT(evaluate_relations(est, relations, {}).translation_m.max, 1e-12);
  // Scan 8 has no pose, only poses 100 us before and after it: missing, not interpolated.
  const int64_t t8 = est[8].utime;
  est.erase(est.begin() + 8);
  est.push_back({t8 - 100, t[8].pose});
  est.push_back({t8 + 100, t[8].pose});
  RelationsConfig strict;
  strict.min_share = 0.5;
  RelationsEvaluation ev = evaluate_relations(est, relations, strict);
  EXPECT_EQ(ev.used, 1u);
  EXPECT_EQ(ev.missing, 1u);
  EXPECT_TRUE(ev.checks[1].has_t1);
  EXPECT_FALSE(ev.checks[1].has_t2);
  EXPECT_DOUBLE_EQ(ev.share, 0.5);
  EXPECT_FALSE(ev.refused);
  // A tolerance of 100 us takes the nearer pose (the first of two at the same distance).
  RelationsConfig tolerant = strict;
  tolerant.time_tolerance_us = 100;
  ev = evaluate_relations(est, relations, tolerant);
  EXPECT_EQ(ev.used, 2u);
}

TEST(Relations, TooFewUsedAreRefused) {
  std::mt19937 rng(4);
  const Trajectory t = truth(20, rng);
  std::vector<Relation> relations;
  for (std::size_t i = 0; i + 1 < t.size(); ++i) relations.push_back(relation(t, i, i + 1));
  // One pose: the "perfect run" of a stage that published a single pose.
  const Trajectory one = {t[0]};
  const RelationsEvaluation ev = evaluate_relations(one, relations, {});
  EXPECT_EQ(ev.used, 0u);
  EXPECT_EQ(ev.missing, relations.size());
  EXPECT_TRUE(ev.refused);
  EXPECT_TRUE(evaluate_relations(t, {}, {}).refused);  // nothing to score against
  // 15 of 19 used: 79 %, below the default 80 %.
  const Trajectory most(t.begin(), t.begin() + 16);
  EXPECT_TRUE(evaluate_relations(most, relations, {}).refused);
  EXPECT_FALSE(evaluate_relations(Trajectory(t.begin(), t.begin() + 17), relations, {}).refused);
}

TEST(Moments, SampleStandardDeviation) {
  const Moments m = moments({1.0, 2.0, 3.0, 4.0});
  EXPECT_DOUBLE_EQ(m.mean, 2.5);
  EXPECT_DOUBLE_EQ(m.sd, std::sqrt(5.0 / 3.0));
  EXPECT_DOUBLE_EQ(m.max, 4.0);
  EXPECT_DOUBLE_EQ(moments({7.0}).sd, 0.0);
  EXPECT_DOUBLE_EQ(moments({}).mean, 0.0);
}

TEST(RelationsFile, ReadsStampsExactlyAndCountsMalformedLines) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("traverse-relations-" + std::to_string(::getpid()) + ".relations");
  std::ofstream(path) << "976052905.167303 976052911.885496 -0.056990 -0.128430 0 0 0 -1.682210\n"
                      << "# a comment\n\n"
                      << "1 2 3\n"
                      << "1 2 nan 0 0 0 0 0\n"
                      << "90.239599 90.719599 0.422330 -0.000750 0.0 0.0 0.0 0.017260\n";
  const RelationsFile f = read_relations(path.string());
  EXPECT_TRUE(f.error.empty());
  ASSERT_EQ(f.relations.size(), 2u);
  EXPECT_EQ(f.relations[0].t1_utime, 976'052'905'167'303);
  EXPECT_EQ(f.relations[0].t2_utime, 976'052'911'885'496);
  EXPECT_DOUBLE_EQ(f.relations[0].T_1_2.x(), -0.05699);
  EXPECT_DOUBLE_EQ(f.relations[0].T_1_2.theta(), -1.68221);
  EXPECT_EQ(f.relations[0].line, 1);
  EXPECT_EQ(f.relations[1].t1_utime, 90'239'599);
  EXPECT_EQ(f.relations[1].line, 6);
  EXPECT_EQ(f.malformed_count, 2);
  EXPECT_EQ(f.malformed_lines, (std::vector<int64_t>{4, 5}));
  std::filesystem::remove(path);
  EXPECT_FALSE(read_relations("/nonexistent/x.relations").error.empty());
}

// The benchmark's files: every line a relation, and every stamp a scan's of the log.
TEST(RelationsFile, TheSharedRelationsParse) {
  for (const auto& [name, count] : std::vector<std::pair<std::string, std::size_t>>{
           {"intel", 2984}, {"aces", 1279}, {"fr079", 1685}}) {
    const std::string path = "../shared/data/kummerle/" + name + ".relations";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "no data at " << path;
    const RelationsFile f = read_relations(path);
    EXPECT_EQ(f.relations.size(), count) << name;
    EXPECT_EQ(f.malformed_count, 0) << name;
  }
}

}  // namespace
}  // namespace traverse::evaluator
