// A listener that starts after the densifier and the mapper (resend.hpp, docs/late-joining.md):
// what each answers, the mapper's answer under its cap (preview.resend_max_bytes), and how the
// mapper paces its answers (resend.pace_s).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <thread>
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

// The mapper paces its answer like the densifier and the annotator (resend.hpp: per requester, by
// data time, here the newest profile's). Its answer goes out over several calls of publish_preview
// (64 KB per 100 ms), so a request can come while it is still going out.
class PreviewPacingTest : public GraphTest {
 protected:
  void SetUp() override {
    GraphTest::SetUp();
    bus_.subscribe<cloud_preview_t>(channels::kCloudPreview,
                                    [this](const cloud_preview_t& m) { preview_.push_back(m); });
    // In any order, as the viewer reads it: an answer that goes round for a requester who joined
    // goes back to the oldest profile.
    bus_.subscribe<cloud_preview_t>(
        channels::full_channel(channels::kCloudPreview),
        [this](const cloud_preview_t& m) { again_.push_back(m); }, true);
  }
  void ask(const std::string& who) {
    request_resend(bus_, who, {channels::kCloudPreview});
    handle_all();
  }
  void publish() {
    mapper_->flush();
    mapper_->publish_preview();
    handle_all();
  }
  // Publishes until a call after the byte window (100 ms of wall time) sends nothing more: the
  // answer is out, however slow the machine.
  void finish_answer() {
    for (int calls = 0; calls < 1000; ++calls) {
      const std::size_t before = again_.size();
      std::this_thread::sleep_for(std::chrono::milliseconds(110));
      publish();
      if (again_.size() == before) return;
    }
    FAIL() << "the answer never ended";
  }
  double counter(const std::string& name) {
    mapper_->report_counters();
    return mapper_counters_.at(name);
  }
  static int64_t points(const std::vector<cloud_preview_t>& messages) {
    int64_t n = 0;
    for (const auto& [t, pts] : preview_points(messages)) n += static_cast<int64_t>(pts.size());
    return n;
  }

  std::vector<cloud_preview_t> preview_, again_;
};

// A burst from one requester gets one answer, a second requester is answered at once (it joins
// the answer before any of it went out, so both get it whole once), and a request from a requester
// whose answer is still going out is dropped, even past its stretch; once the answer is out and
// the stretch over, the same requester is answered again.
class BurstPacingTest : public PreviewPacingTest {
 protected:
  void configure(mapper::MapperConfig& c) override {
    c.preview.cell_m = 0.01;  // a store several times what one call of publish_preview sends
    c.preview.max_points_per_message = 1000;
  }
};

TEST_P(BurstPacingTest, ABurstGetsOneAnswerAndARequestWhileItGoesOutDoesNotRestartIt) {
  drive(300, true);  // 6 s of data
  publish();
  for (int k = 0; k < 4; ++k) ask("viewer");
  ask("second-viewer");  // not answered yet: answered at once
  EXPECT_EQ(counter("resend_answers"), 2.0);
  EXPECT_EQ(counter("resend_requests_paced"), 3.0);
  publish();
  RecordProperty("first_call_points", std::to_string(points(again_)));
  RecordProperty("live_points", std::to_string(points(preview_)));
  ASSERT_GT(points(again_), 0);
  ASSERT_LT(points(again_), points(preview_)) << "the answer went out at once: enlarge the store";
  drive(600, true, 301);  // 6 s more: past the viewer's 5 s stretch
  ask("viewer");          // its answer is still going out
  EXPECT_EQ(counter("resend_answers"), 2.0);
  EXPECT_EQ(counter("resend_requests_paced"), 4.0);
  finish_answer();
  // Every point sent live, once: the answer was not restarted (it would repeat its start).
  EXPECT_TRUE(preview_points(again_) == preview_points(preview_))
      << points(again_) << " points answered, " << points(preview_) << " sent live";
  ask("viewer");  // the answer out, 6 s after it began
  EXPECT_EQ(counter("resend_requests"), 7.0);
  EXPECT_EQ(counter("resend_answers"), 3.0);
  EXPECT_EQ(counter("resend_requests_paced"), 4.0);
}

// A second requester that asks while an answer goes out joins it (PreviewResend::answer): the
// answer is not restarted but goes on in time order to the newest profile, then round from the
// oldest to where it stood when the second asked. Each gets every stored point after asking, and
// no point goes more than twice.
class JoinPacingTest : public BurstPacingTest {};

TEST_P(JoinPacingTest, ASecondRequesterJoinsTheAnswerUnderWayInsteadOfRestartingIt) {
  drive(300, true);  // 6 s of data
  publish();
  using Points = std::map<int64_t, std::vector<std::array<int16_t, 3>>>;
  const Points stored_first = preview_points(preview_);  // the store when the first asks
  ask("viewer");
  publish();  // the answer's first window
  const std::size_t before_join = again_.size();
  ASSERT_GT(before_join, 0u);
  ASSERT_LT(points(again_), points(preview_)) << "the answer went out at once: enlarge the store";
  const int64_t joined_at = again_.back().profiles.back().utime;
  drive(320, true, 301);  // 0.4 s of data later
  const Points stored_second = preview_points(preview_);
  ask("second-viewer");
  finish_answer();
  EXPECT_EQ(counter("resend_answers"), 2.0);
  EXPECT_EQ(counter("resend_requests_joined"), 1.0);
  EXPECT_EQ(counter("resend_requests_paced"), 0.0);

  // Each requester gets every point stored when it asked, at least once after asking.
  const auto count = [](const Points& points) {
    std::map<std::pair<int64_t, std::array<int16_t, 3>>, int> n;
    for (const auto& [t, pts] : points) {
      for (const auto& p : pts) ++n[{t, p}];
    }
    return n;
  };
  const auto answered_first = count(preview_points(again_));
  const auto answered_second = count(
      preview_points({again_.begin() + static_cast<std::ptrdiff_t>(before_join), again_.end()}));
  int missed_first = 0, missed_second = 0;
  for (const auto& [key, n] : count(stored_first)) {
    const auto it = answered_first.find(key);
    missed_first += it == answered_first.end() || it->second < n;
  }
  for (const auto& [key, n] : count(stored_second)) {
    const auto it = answered_second.find(key);
    missed_second += it == answered_second.end() || it->second < n;
  }
  EXPECT_EQ(missed_first, 0);
  EXPECT_EQ(missed_second, 0);
  // No point more than twice as often as it was sent live.
  const auto live = count(preview_points(preview_));
  int over_twice = 0;
  for (const auto& [key, n] : answered_first) over_twice += n > 2 * live.at(key);
  EXPECT_EQ(over_twice, 0);

  // Not restarted: in time order to the newest profile, then once round from the oldest, to no
  // further than where the answer stood when the second asked.
  std::vector<int64_t> order;
  for (const cloud_preview_t& m : again_) {
    for (const preview_profile_t& p : m.profiles) order.push_back(p.utime);
  }
  const auto round = std::is_sorted_until(order.begin(), order.end());
  ASSERT_NE(round, order.end()) << "the answer never went round for the second requester";
  EXPECT_EQ(*(round - 1), live.rbegin()->first.first) << "went round before the newest profile";
  EXPECT_EQ(*round, live.begin()->first.first);
  EXPECT_TRUE(std::is_sorted(round, order.end())) << "started again a second time";
  EXPECT_LE(order.back(), joined_at);
}

// resend.pace_s of the mapper's config is the stretch: with 1 s, a request 0.5 s of data after
// the answer is dropped, one 1.5 s after is answered (the default 5 s would drop it).
class ConfiguredPacingTest : public PreviewPacingTest {
 protected:
  void configure(mapper::MapperConfig& c) override { c.resend.pace_s = 1.0; }
};

TEST_P(ConfiguredPacingTest, ARequestPastTheConfiguredStretchIsAnswered) {
  drive(100, true);  // the newest profile at 1.92 s
  publish();
  ask("viewer");
  finish_answer();
  EXPECT_TRUE(preview_points(again_) == preview_points(preview_))
      << points(again_) << " points answered, " << points(preview_) << " sent live";
  drive(125, true, 101);  // newest profile at 2.46 s
  ask("viewer");
  EXPECT_EQ(counter("resend_answers"), 1.0);
  EXPECT_EQ(counter("resend_requests_paced"), 1.0);
  drive(175, true, 126);  // newest profile at 3.42 s
  ask("viewer");
  EXPECT_EQ(counter("resend_answers"), 2.0);
  EXPECT_EQ(counter("resend_requests_paced"), 1.0);
}

INSTANTIATE_TEST_SUITE_P(Mapper, BurstPacingTest, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "worker" : "inline"; });

INSTANTIATE_TEST_SUITE_P(Mapper, JoinPacingTest, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "worker" : "inline"; });

INSTANTIATE_TEST_SUITE_P(Mapper, ConfiguredPacingTest, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "worker" : "inline"; });

INSTANTIATE_TEST_SUITE_P(Mapper, SmallResendTest, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "worker" : "inline"; });

INSTANTIATE_TEST_SUITE_P(Mapper, LateJoinGraphTest, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "worker" : "inline"; });

}  // namespace
}  // namespace traverse
