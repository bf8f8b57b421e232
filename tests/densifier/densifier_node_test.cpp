// Packing of segments into DENSE_SEGMENTS messages: in order, each message under the size limit
// unless one segment alone is larger (then it travels alone), parts numbered 0..parts-1. A late
// listener's requests are answered on DENSE_SEGMENTS_FULL, paced by frontend time.
#include "densifier_node.hpp"

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>

#include "channels.hpp"

namespace traverse::densifier {
namespace {

Segment make_segment(int64_t id, int n_poses) {
  Segment s;
  s.key_id_first = id;
  s.key_id_last = id + 1;
  s.revision = 3;
  for (int i = 0; i < n_poses; ++i) {
    s.poses.push_back({1'000'000 * id + 1000 * i, Pose2(0.1 * i, 0.01 * id, 0.001 * i)});
  }
  return s;
}

TEST(PackSegments, FillsMessagesUpToTheLimitInOrder) {
  std::vector<Segment> segments;
  for (int k = 0; k < 200; ++k) segments.push_back(make_segment(k, 10 + k % 7));
  constexpr int kLimit = 8000;
  const auto messages = pack_segments(segments, "world", "base", 7, kLimit);
  ASSERT_GT(messages.size(), 1u);
  int64_t next_id = 0;
  std::size_t total_bytes = 0;
  for (std::size_t i = 0; i < messages.size(); ++i) {
    const dense_segments_t& m = messages[i];
    EXPECT_LE(m.getEncodedSize(), kLimit);
    total_bytes += m.getEncodedSize();
    EXPECT_EQ(m.part, static_cast<int32_t>(i));
    EXPECT_EQ(m.parts, static_cast<int32_t>(messages.size()));
    EXPECT_EQ(m.optimisation, 7);
    EXPECT_EQ(m.parent_frame, "world");
    EXPECT_EQ(m.child_frame, "base");
    ASSERT_EQ(m.n_segments, static_cast<int32_t>(m.segments.size()));
    for (const dense_segment_t& s : m.segments) {
      EXPECT_EQ(s.key_id_first, next_id++);
      EXPECT_EQ(s.revision, 3);
      EXPECT_EQ(s.n_poses, static_cast<int32_t>(s.pose_utime.size()));
    }
  }
  EXPECT_EQ(next_id, 200);
  // Greedy filling: no two neighbouring messages would have fitted into one.
  for (std::size_t i = 0; i + 1 < messages.size(); ++i) {
    dense_segments_t first_of_next = messages[i];
    first_of_next.segments.push_back(messages[i + 1].segments.front());
    ++first_of_next.n_segments;
    EXPECT_GT(first_of_next.getEncodedSize(), kLimit);
  }
  EXPECT_GT(total_bytes, (messages.size() - 1) * kLimit * 9 / 10);
}

TEST(PackSegments, SegmentLargerThanTheLimitTravelsAlone) {
  std::vector<Segment> segments = {make_segment(0, 5), make_segment(1, 400), make_segment(2, 5)};
  const auto messages = pack_segments(segments, "world", "base", 1, 4096);  // 400 poses: 12.8 kB
  ASSERT_EQ(messages.size(), 3u);
  EXPECT_EQ(messages[1].n_segments, 1);
  EXPECT_GT(messages[1].getEncodedSize(), 4096);
  EXPECT_LE(messages[0].getEncodedSize(), 4096);
  EXPECT_LE(messages[2].getEncodedSize(), 4096);
}

TEST(PackSegments, NothingToSendGivesNoMessage) {
  EXPECT_TRUE(pack_segments({}, "world", "base", 0, 60000).empty());
}

// A late listener's requests to a densifier node over memq://, with frontend poses at 10 Hz and a
// key pose a second driven along x.
class DensifierNodeResend : public ::testing::Test {
 protected:
  void start(const DensifierConfig& config) {
    node_ = std::make_unique<DensifierNode>(
        bus_, config, [this](const std::string& k, double v) { counters_[k] = v; });
    bus_.subscribe<dense_segments_t>(
        channels::full_channel(channels::kDenseSegments),
        [this](const dense_segments_t& m) {
          answers_ += m.part == 0;
          if (answers_ == 1) answered_segments_ += m.n_segments;
        },
        true);
  }
  void handle_all() {
    while (bus_.lcm().handleTimeout(0) > 0) {
    }
  }
  void drive(int from, int to) {
    constexpr int64_t kDt = 100'000;  // [us]
    for (int i = from; i < to; ++i) {
      pose2d_t p{};
      p.utime = i * kDt;
      p.parent_frame = "map";
      p.child_frame = "base";
      p.x = 0.05 * i;  // [m] 0.5 m/s along x
      bus_.publish(channels::kPoseFrontend, p);
      if (i % 10 == 0) {
        key_poses_t k{};
        k.utime = p.utime;
        k.optimisation = i / 10 + 1;
        k.parts = 1;
        key_pose_t pose{};
        pose.utime = p.utime;
        pose.id = i / 10;
        pose.x = p.x;
        k.poses.push_back(pose);
        k.n_poses = 1;
        bus_.publish(channels::kKeyPoses, k);
      }
      handle_all();
    }
  }
  void ask(const std::string& who) {
    request_resend(bus_, who, {channels::kDenseSegments});
    handle_all();
  }
  double counter(const std::string& name) {
    node_->report_counters();
    return counters_.at(name);
  }

  Bus bus_{"memq://"};
  std::map<std::string, double> counters_;
  std::unique_ptr<DensifierNode> node_;
  int answers_ = 0;            // answers on DENSE_SEGMENTS_FULL
  int answered_segments_ = 0;  // ... the first one's segments
};

// A burst of requests from one requester gets one answer per resend.pace_s (5 s by default) of
// frontend time (common/resend.hpp); a requester not answered yet is answered inside that stretch.
TEST_F(DensifierNodeResend, ABurstGetsOneAnswerPerStretchAndANewRequesterIsAnswered) {
  start(DensifierConfig{});
  drive(0, 60);  // 5.9 s of data, five segments closed
  for (int k = 0; k < 4; ++k) ask("viewer");
  EXPECT_EQ(answers_, 1);
  EXPECT_GE(answered_segments_, 4);
  ask("second-viewer");  // not answered yet: answered inside the first one's stretch
  EXPECT_EQ(answers_, 2);
  drive(60, 100);  // 4 s after the answer: still inside the stretch
  ask("viewer");
  EXPECT_EQ(answers_, 2);
  drive(100, 120);  // 6 s after
  ask("viewer");
  EXPECT_EQ(answers_, 3);
  EXPECT_EQ(counter("resend_requests"), 7.0);
  EXPECT_EQ(counter("resend_answers"), 3.0);
  EXPECT_EQ(counter("resend_requests_paced"), 4.0);
}

// The stretch is the config's resend.pace_s: with 1 s, a request 0.5 s of frontend time after the
// answer is dropped and one 1.5 s after is answered (the default would drop both).
TEST_F(DensifierNodeResend, TheConfiguredPaceIsTheStretch) {
  DensifierConfig config;
  config.resend.pace_s = 1.0;
  ASSERT_FALSE(validate(config));
  start(config);
  drive(0, 60);
  ask("viewer");
  drive(60, 65);
  ask("viewer");
  EXPECT_EQ(answers_, 1);
  drive(65, 75);
  ask("viewer");
  EXPECT_EQ(answers_, 2);
  EXPECT_EQ(counter("resend_requests_paced"), 1.0);
  config.resend.pace_s = -1.0;
  EXPECT_NE(validate(config).value_or("").find("'resend.pace_s'"), std::string::npos);
}

}  // namespace
}  // namespace traverse::densifier
