// A listener that starts after the densifier and the mapper (resend.hpp, docs/late-joining.md):
// what each answers, and the mapper's answer under its cap (preview.resend_max_bytes).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "graph_fixture.hpp"
#include "resend.hpp"

namespace traverse {
namespace {

class LateJoinGraphTest : public GraphTest {};

// The preview's points per profile time, as a viewer puts the parts of a profile together.
std::map<int64_t, std::vector<std::array<int16_t, 3>>> preview_points(
    const std::vector<cloud_preview_t>& messages) {
  std::map<int64_t, std::vector<std::array<int16_t, 3>>> out;
  for (const cloud_preview_t& m : messages) {
    for (const preview_profile_t& p : m.profiles) {
      for (int i = 0; i < p.n_points; ++i)
        out[p.utime].push_back({p.x_mm[i], p.y_mm[i], p.z_mm[i]});
    }
  }
  return out;
}

// A listener that starts late asks once for what came before (resend.hpp): the densifier answers
// with the newest revision of every segment on DENSE_SEGMENTS_FULL, the mapper with every preview
// point it sent (under its cap) on CLOUD_PREVIEW_FULL, and neither answer reaches the incremental
// channels. The mapper, in turn, takes the annotator's answer on ANNOTATIONS_FULL like ANNOTATIONS.
TEST_P(LateJoinGraphTest, ALateListenerGetsEverySegmentAndPreviewProfileAgain) {
  std::vector<cloud_preview_t> preview, preview_again;
  std::vector<dense_segment_t> segments_again;
  bus_.subscribe<cloud_preview_t>(channels::kCloudPreview,
                                  [&](const cloud_preview_t& m) { preview.push_back(m); });
  bus_.subscribe<cloud_preview_t>(channels::full_channel(channels::kCloudPreview),
                                  [&](const cloud_preview_t& m) { preview_again.push_back(m); });
  bus_.subscribe<dense_segments_t>(
      channels::full_channel(channels::kDenseSegments), [&](const dense_segments_t& m) {
        segments_again.insert(segments_again.end(), m.segments.begin(), m.segments.end());
      });
  drive(100, true);
  send_keys({5, 6}, 0.05);  // segments 4 and 5 move: revision 1
  handle_all();
  mapper_->flush();
  mapper_->publish_preview();
  handle_all();
  ASSERT_GT(preview.size(), 0u);
  const std::size_t segments_sent = segments_.size();
  EXPECT_TRUE(preview_again.empty() && segments_again.empty());  // nobody asked yet

  request_resend(bus_, "test", {channels::kDenseSegments, channels::kCloudPreview});
  handle_all();
  mapper_->publish_preview();  // the mapper answers from its own thread, paced
  handle_all();
  EXPECT_EQ(segments_.size(), segments_sent);  // nothing more on DENSE_SEGMENTS
  ASSERT_EQ(segments_again.size(), 6u);
  for (std::size_t i = 0; i < segments_again.size(); ++i) {
    EXPECT_EQ(segments_again[i].key_id_first, static_cast<int64_t>(i));
    EXPECT_EQ(segments_again[i].revision, i >= 4 ? 1 : 0);
  }
  EXPECT_NEAR(segments_again[5].y.front(), 0.05, 1e-12);
  EXPECT_EQ(preview_points(preview_again), preview_points(preview));

  annotations_t a{};
  a.utime = kT0;
  a.parts = 1;
  a.keys.resize(2);
  a.keys[0].id = 0;
  a.keys[0].utime = kT0;
  a.keys[1].id = 1;
  a.keys[1].utime = kT0 + kKeyEvery * kPoseDt;
  a.n_keys = 2;
  bus_.publish(channels::full_channel(channels::kAnnotations), a);
  handle_all();
  mapper_->report_counters();
  EXPECT_EQ(mapper_counters_.at("annotated_key_poses"), 2.0);
  EXPECT_EQ(mapper_counters_.at("resend_answers"), 1.0);
  EXPECT_EQ(mapper_counters_.at("resend_requests"), 1.0);
  EXPECT_EQ(mapper_counters_.at("resend_requests_sent"), 1.0);  // the annotations, at start
}

// The mapper keeps what it resends under preview.resend_max_bytes: after a run longer than that,
// the late listener gets fewer points than were sent live, never more bytes than the cap, and
// still the whole route, its start included (the earliest point of each coarser cell is kept).
class SmallResendTest : public GraphTest {
 protected:
  void SetUp() override {
    resend_max_bytes_ = 4 << 10;
    GraphTest::SetUp();
  }
};

TEST_P(SmallResendTest, ALateListenerGetsTheWholeRouteUnderTheCap) {
  std::vector<cloud_preview_t> preview, preview_again;
  bus_.subscribe<cloud_preview_t>(channels::kCloudPreview,
                                  [&](const cloud_preview_t& m) { preview.push_back(m); });
  bus_.subscribe<cloud_preview_t>(channels::full_channel(channels::kCloudPreview),
                                  [&](const cloud_preview_t& m) { preview_again.push_back(m); });
  drive(300, true);  // 6 s, 3 m
  mapper_->flush();
  mapper_->publish_preview();
  handle_all();
  request_resend(bus_, "test", {channels::kCloudPreview});
  handle_all();
  mapper_->flush();  // a thinning pass still under way (live, on a thread of its own) done
  mapper_->publish_preview();
  handle_all();
  const auto live = preview_points(preview), again = preview_points(preview_again);
  int64_t live_points = 0, again_points = 0;
  for (const auto& [t, pts] : live) live_points += static_cast<int64_t>(pts.size());
  for (const auto& [t, pts] : again) {
    again_points += static_cast<int64_t>(pts.size());
    ASSERT_TRUE(live.count(t)) << t;  // points of profiles sent live, nothing made up
    for (const auto& q : pts) {
      EXPECT_NE(std::find(live.at(t).begin(), live.at(t).end(), q), live.at(t).end());
    }
  }
  mapper_->report_counters();
  RecordProperty("live_points", std::to_string(live_points));
  RecordProperty("resent_points", std::to_string(again_points));
  ASSERT_GT(live_points * 6, 2 * resend_max_bytes_);  // a run longer than the cap
  EXPECT_GT(again_points, 0);
  EXPECT_LT(again_points, live_points);
  EXPECT_LE(mapper_counters_.at("preview_resend_bytes"), static_cast<double>(resend_max_bytes_));
  EXPECT_LE(again_points * 6, resend_max_bytes_);
  EXPECT_GT(mapper_counters_.at("preview_resend_compactions"), 0.0);
  EXPECT_EQ(mapper_counters_.at("preview_resend_points_compacted"),
            static_cast<double>(live_points - again_points));
  // The start and the end of the route: the first profile (its points are the earliest of their
  // cells), and one of the last second.
  EXPECT_EQ(again.begin()->first, live.begin()->first);
  EXPECT_GT(again.rbegin()->first, live.rbegin()->first - 1'000'000);
}

INSTANTIATE_TEST_SUITE_P(Mapper, SmallResendTest, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "worker" : "inline"; });

INSTANTIATE_TEST_SUITE_P(Mapper, LateJoinGraphTest, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "worker" : "inline"; });

}  // namespace
}  // namespace traverse
