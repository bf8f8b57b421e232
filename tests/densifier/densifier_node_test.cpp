// Packing of segments into DENSE_SEGMENTS messages: in order, each message under the size limit
// unless one segment alone is larger (then it travels alone), parts numbered 0..parts-1.
#include "densifier_node.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace traverse::densifier
