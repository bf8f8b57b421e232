// The annotator on a synthetic corridor there and back: absolute bounds grow along the chain and
// drop after a loop closure, local bounds stay small, levels and colours follow the bound, only
// changes are returned, and bad edges are counted.
#include "annotator.hpp"

#include <gtest/gtest.h>

namespace traverse::annotator {
namespace {

constexpr int kKeys = 40;

// A straight chain of key poses 0.5 m apart (5 mm, 2 mrad per link); with `closure`, a link from
// the last back to the first as well (the platform came back).
backend::PoseGraph chain(bool closure) {
  backend::PoseGraph g;
  for (int i = 0; i < kKeys; ++i) g.add_vertex(i, Pose2(0.5 * i, 0.0, 0.0), i == 0);
  auto add = [&](int from, int to) {
    backend::Edge e;
    e.from = from;
    e.to = to;
    e.T_from_to = between(g.poses[from], g.poses[to]);
    e.information = Eigen::Vector3d(1 / 25e-6, 1 / 25e-6, 1 / 4e-6).asDiagonal();
    g.edges.push_back(e);
  };
  for (int i = 0; i + 1 < kKeys; ++i) add(i, i + 1);
  if (closure) add(kKeys - 1, 0);
  return g;
}

// Feeds the graph to the annotator as the backend would: edges, then key poses with marginals.
std::vector<Annotation> feed(Annotator& a, backend::PoseGraph g, std::size_t first_edge = 0) {
  JointCovariance joint;
  EXPECT_TRUE(joint.factor(g));
  for (std::size_t k = first_edge; k < g.edges.size(); ++k) {
    const backend::Edge& e = g.edges[k];
    EXPECT_TRUE(a.add_edge(static_cast<int>(k), e.from, e.to, e.T_from_to, e.information));
  }
  for (int i = 0; i < kKeys; ++i) a.set_key_pose(i, 1000 * i, g.poses[i], joint.marginal(i));
  return a.update();
}

AnnotatorConfig config() {
  AnnotatorConfig c;
  c.best_level = "LOA40";
  c.worst_level = "LOA20";
  c.local_radius_m = 2.0;
  return c;
}

TEST(Annotator, BoundsGrowAlongTheChainAndLocalOnesStaySmall) {
  Annotator a(config());
  const auto out = feed(a, chain(false));
  ASSERT_EQ(out.size(), static_cast<std::size_t>(kKeys));
  EXPECT_EQ(out[0].bound_m, 0.0);
  for (int i = 2; i < kKeys; ++i) {
    EXPECT_GT(out[i].bound_m, out[i - 1].bound_m) << i;
    EXPECT_GE(out[i].level, out[i - 1].level) << i;
    EXPECT_EQ(out[i].rgb, a.legend().levels()[out[i].level].rgb);
  }
  // 39 links of 5 mm and a heading random walk over 19.5 m: far beyond LOA20's 50 mm.
  EXPECT_GT(out.back().bound_m, 0.05);
  EXPECT_EQ(out.back().level, 4);
  EXPECT_EQ(out.back().rgb, (Rgb{255, 0, 0}));
  // Locally (within 2 m: four links each way) the chain is good to about two centimetres.
  EXPECT_GT(out.back().local_bound_m, 0.0);
  EXPECT_LT(out.back().local_bound_m, 0.3 * out.back().bound_m);
  EXPECT_NEAR(out[20].local_bound_m, out[30].local_bound_m, 0.2 * out[20].local_bound_m);
}

TEST(Annotator, LoopClosureShrinksTheFarBoundsAndChangesTheirLevel) {
  AnnotatorConfig c = config();
  c.limits_m = {0.01, 0.03, 0.1, 0.2};  // levels that this chain spans
  Annotator a(c);
  const auto before = feed(a, chain(false));
  const auto after = feed(a, chain(true), chain(false).edges.size());
  EXPECT_GT(a.last_level_changes(), 0);
  std::map<int64_t, Annotation> now;
  for (const Annotation& x : after) now[x.id] = x;
  // A new edge only adds information: no bound grows; the end of the chain, now tied to the
  // first key pose 19.5 m away (a 2 mrad heading link: about 4 cm sideways), drops most.
  for (const auto& [id, x] : a.annotations()) EXPECT_LE(x.bound_m, before[id].bound_m + 1e-12);
  for (int i = 30; i < kKeys; ++i) {
    ASSERT_TRUE(now.count(i)) << i;
    EXPECT_LT(now[i].bound_m, 0.6 * before[i].bound_m) << i;
  }
  EXPECT_EQ(before[kKeys - 1].level, 4);
  EXPECT_LT(now[kKeys - 1].level, 4);
  EXPECT_NE(now[kKeys - 1].rgb, before[kKeys - 1].rgb);
}

TEST(Annotator, ReturnsOnlyWhatChanged) {
  Annotator a(config());
  feed(a, chain(false));
  backend::PoseGraph g = chain(false);
  JointCovariance joint;
  ASSERT_TRUE(joint.factor(g));
  a.set_key_pose(10, 10000, g.poses[10], joint.marginal(10));  // the same again
  EXPECT_TRUE(a.update().empty());
  a.set_key_pose(10, 10000, g.poses[10], 4.0 * joint.marginal(10));  // bound doubles
  const auto out = a.update();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, 10);
}

TEST(Annotator, ColoursByTheLocalBoundWhenAsked) {
  AnnotatorConfig c = config();
  c.colour_by = "local";
  Annotator a(c);
  const auto out = feed(a, chain(false));
  EXPECT_EQ(out.back().level, a.legend().level_of(out.back().local_bound_m));
  EXPECT_LT(out.back().level, 4);
}

TEST(Annotator, ScaleMultipliesTheCovariance) {
  AnnotatorConfig c = config();
  Annotator plain(c);
  c.covariance_scale = 9.0;
  Annotator scaled(c);
  const auto p = feed(plain, chain(false)), s = feed(scaled, chain(false));
  EXPECT_NEAR(s[20].bound_m, 3.0 * p[20].bound_m, 1e-9);
  EXPECT_NEAR(s[20].local_bound_m, 3.0 * p[20].local_bound_m, 1e-9);
}

TEST(Annotator, BadAndMissingEdgesAreCounted) {
  Annotator a(config());
  const Eigen::Matrix3d good = Eigen::Matrix3d::Identity();
  EXPECT_TRUE(a.add_edge(0, 0, 1, Pose2(1, 0, 0), good));
  EXPECT_TRUE(a.add_edge(0, 0, 1, Pose2(1, 0, 0), good));   // repeat: ignored
  EXPECT_FALSE(a.add_edge(3, 1, 2, Pose2(1, 0, 0), good));  // 1 and 2 were lost
  EXPECT_EQ(a.counters().edge_gaps, 2);
  Eigen::Matrix3d bad = good;
  bad(2, 2) = -1.0;
  EXPECT_FALSE(a.add_edge(1, 1, 2, Pose2(1, 0, 0), bad));
  EXPECT_EQ(a.counters().edges_rejected, 1);
  EXPECT_EQ(a.counters().edges, 1);
  // The refused edge took its index: the next one is taken, not counted as missed.
  EXPECT_TRUE(a.add_edge(2, 1, 2, Pose2(1, 0, 0), good));
  EXPECT_EQ(a.counters().edges, 2);
  EXPECT_EQ(a.counters().edge_gaps, 2);
  // A held link's information as the backend inverted it: terms from 0.1 to 1e6, off the
  // diagonal asymmetric by 1e-6 (rounding, 1e-12 of its norm) is taken; by 1 % it is refused.
  Eigen::Matrix3d held;
  held << 0.1, 2.0, 30.0, 2.0, 5e4, 40.0, 30.0, 40.0, 1e6;
  held(0, 2) += 1.1e-6;
  EXPECT_TRUE(a.add_edge(3, 2, 3, Pose2(1, 0, 0), held));
  EXPECT_EQ(a.counters().edges, 3);
  Eigen::Matrix3d skewed = held;
  skewed(1, 2) *= 1.5;
  skewed(1, 2) += 0.01 * held.norm();
  EXPECT_FALSE(a.add_edge(4, 3, 4, Pose2(1, 0, 0), skewed));
  EXPECT_EQ(a.counters().edges_rejected, 2);
}

TEST(Annotator, ConfigValidationNamesTheKey) {
  AnnotatorConfig c;
  EXPECT_FALSE(validate(c));
  c.bound = "twice";
  EXPECT_NE(validate(c).value_or("").find("bound"), std::string::npos);
  c = AnnotatorConfig{};
  c.colour_by = "local";
  c.local_radius_m = 0.0;
  EXPECT_NE(validate(c).value_or("").find("local_radius_m"), std::string::npos);
  c = AnnotatorConfig{};
  c.covariance_scale = 0.0;
  EXPECT_NE(validate(c).value_or("").find("covariance_scale"), std::string::npos);
  c = AnnotatorConfig{};
  c.worst_level = "LOA99";
  EXPECT_NE(validate(c).value_or("").find("worst_level"), std::string::npos);
}

}  // namespace
}  // namespace traverse::annotator
