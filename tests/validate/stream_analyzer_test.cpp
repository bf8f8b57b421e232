#include "stream_analyzer.hpp"

#include <gtest/gtest.h>

#include "test_messages.hpp"

namespace traverse::validate {
namespace {

using test::encode;

class StreamAnalyzerTest : public ::testing::Test {
 protected:
  template <class T>
  void add(const std::string& channel, int64_t event_utime, const T& msg) {
    const auto bytes = encode(msg);
    a_.add(channel, event_utime, bytes.data(), bytes.size());
  }
  void add_bytes(const std::string& channel, int64_t event_utime, std::vector<uint8_t> bytes) {
    a_.add(channel, event_utime, bytes.data(), bytes.size());
  }
  ChannelSummary get(const std::string& channel) const { return a_.summary().at(channel); }

  StreamAnalyzer a_;
};

TEST_F(StreamAnalyzerTest, CleanStreamCountsRateGapAndFrames) {
  for (int i = 0; i < 11; ++i) add("POSE", 1'000'000 + 100'000 * i, test::make_pose(1000 * i, i));
  const ChannelSummary s = get("POSE");
  EXPECT_EQ(s.type, "traverse.pose2d_t");
  EXPECT_EQ(s.count, 11);
  ASSERT_TRUE(s.rate_hz);
  EXPECT_NEAR(*s.rate_hz, 10.0, 1e-9);
  ASSERT_TRUE(s.max_gap_s);
  EXPECT_NEAR(*s.max_gap_s, 0.1, 1e-9);
  ASSERT_TRUE(s.period_s);
  EXPECT_NEAR(*s.period_s, 0.001, 1e-12);  // from the messages' own utime
  EXPECT_EQ(s.frames, std::set<std::string>{"world->base"});
  EXPECT_TRUE(s.points.empty);
  EXPECT_TRUE(s.clean());
  EXPECT_EQ(s.seq_gaps, 0);
  EXPECT_EQ(a_.events(), 11);
}

TEST_F(StreamAnalyzerTest, LargestGapIsFound) {
  const int64_t times[] = {0, 100, 200, 1200, 1300};
  for (int i = 0; i < 5; ++i) add("POSE", times[i], test::make_pose(times[i], i));
  EXPECT_NEAR(*get("POSE").max_gap_s, 1000e-6, 1e-12);
}

TEST_F(StreamAnalyzerTest, SingleMessageHasNoRateNorGap) {
  add("POSE", 5, test::make_pose(5, 0));
  const ChannelSummary s = get("POSE");
  EXPECT_EQ(s.count, 1);
  EXPECT_FALSE(s.rate_hz);
  EXPECT_FALSE(s.max_gap_s);
  EXPECT_FALSE(s.period_s);
}

TEST_F(StreamAnalyzerTest, ScanFactsPointsSweepAndPeriod) {
  add("SCAN", 0, test::make_scan(0, 0, 180, 0));
  add("SCAN", 20'000, test::make_scan(20'000, 1, 181, 13'000));
  add("SCAN", 40'000, test::make_scan(40'000, 2, 180, 5'000));
  const ChannelSummary s = get("SCAN");
  EXPECT_EQ(s.type, "traverse.planar_scan_t");
  EXPECT_EQ(s.points.min, 180);
  EXPECT_EQ(s.points.max, 181);
  EXPECT_EQ(s.sweep_us.min, 0);
  EXPECT_EQ(s.sweep_us.max, 13'000);
  EXPECT_NEAR(*s.period_s, 0.02, 1e-12);
  EXPECT_EQ(s.frames, std::set<std::string>{"laser_horizontal"});
}

TEST_F(StreamAnalyzerTest, AnotherTypeOnTheChannelIsADecodeFailure) {
  for (int i = 0; i < 5; ++i) add("POSE", i, test::make_pose(i, i));
  add("POSE", 10, test::make_imu(10, 0));
  add("POSE", 11, test::make_imu(11, 1));
  const ChannelSummary s = get("POSE");
  EXPECT_EQ(s.type, "traverse.pose2d_t");  // the type most messages decode as
  EXPECT_EQ(s.count, 7);
  EXPECT_EQ(s.decode_failures, 2);
  EXPECT_EQ(s.other_types.at("traverse.imu_t"), 2);
  EXPECT_FALSE(s.clean());
}

TEST_F(StreamAnalyzerTest, UnknownFingerprintAndShortMessagesAreDecodeFailures) {
  add("POSE", 0, test::make_pose(0, 0));
  add_bytes("POSE", 1, {1, 2, 3});
  add_bytes("POSE", 2, {0xde, 0xad, 0xbe, 0xef, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10});
  add_bytes("POSE", 3, {});
  const ChannelSummary s = get("POSE");
  EXPECT_EQ(s.decode_failures, 3);
  EXPECT_EQ(s.unknown_fingerprint, 3);
}

TEST_F(StreamAnalyzerTest, KnownFingerprintWithBadBytesIsUndecodable) {
  add("SCAN", 0, test::make_scan(0, 0, 10));
  auto cut = encode(test::make_scan(1, 1, 10));
  cut.resize(cut.size() - 3);  // incomplete
  add_bytes("SCAN", 1, cut);
  auto longer = encode(test::make_scan(2, 2, 10));
  longer.push_back(0);  // does not decode *completely*
  add_bytes("SCAN", 2, longer);
  const ChannelSummary s = get("SCAN");
  EXPECT_EQ(s.count, 3);
  EXPECT_EQ(s.decode_failures, 2);
  EXPECT_EQ(s.undecodable, 2);
  EXPECT_EQ(s.points.min, 10);
}

TEST_F(StreamAnalyzerTest, NegativeArrayLengthDoesNotCrash) {
  auto bytes = encode(test::make_scan(0, 0, 4));
  // n_ranges sits right before the 4 ranges and the two empty intensity arrays.
  const std::size_t n_at = bytes.size() - 4 * 4 - 4 - 4 - 4;
  bytes[n_at] = 0xff;  // n_ranges = -2^24 + 4: a corrupt length
  add_bytes("SCAN", 0, bytes);
  EXPECT_EQ(get("SCAN").undecodable, 1);
}

TEST_F(StreamAnalyzerTest, NothingDecodesGivesNoType) {
  add_bytes("JUNK", 0, {9, 9, 9, 9, 9, 9, 9, 9, 9});
  const ChannelSummary s = get("JUNK");
  EXPECT_EQ(s.type, "");
  EXPECT_EQ(s.decode_failures, 1);
}

TEST_F(StreamAnalyzerTest, EventTimeGoingBackwardsIsCountedPerStep) {
  const int64_t times[] = {100, 200, 500, 300, 400, 600};  // one late event
  for (int i = 0; i < 6; ++i) add("POSE", times[i], test::make_pose(times[i], i));
  const ChannelSummary s = get("POSE");
  EXPECT_EQ(s.event_backwards, 1);
  EXPECT_EQ(s.utime_backwards, 1);
  EXPECT_EQ(s.backwards, 1);  // one message, both of its times went back
  EXPECT_NEAR(*s.max_backstep_s, 200e-6, 1e-12);
  EXPECT_NEAR(*s.max_gap_s, 300e-6, 1e-12);
  EXPECT_FALSE(s.clean());
}

TEST_F(StreamAnalyzerTest, MessageUtimeBackwardsWithOrderedEventTime) {
  // A logger stamps receive times in order; the producer's own clock jumped back.
  const int64_t utimes[] = {10, 20, 15, 30};
  for (int i = 0; i < 4; ++i) add("POSE", 1000 * i, test::make_pose(utimes[i], i));
  const ChannelSummary s = get("POSE");
  EXPECT_EQ(s.event_backwards, 0);
  EXPECT_EQ(s.utime_backwards, 1);
  EXPECT_EQ(s.backwards, 1);
  EXPECT_NEAR(*s.max_backstep_s, 5e-6, 1e-12);
  EXPECT_FALSE(s.clean());
}

TEST_F(StreamAnalyzerTest, EqualTimestampsAreNotBackwards) {
  add("POSE", 7, test::make_pose(7, 0));
  add("POSE", 7, test::make_pose(7, 1));
  EXPECT_EQ(get("POSE").backwards, 0);
  EXPECT_FALSE(get("POSE").max_backstep_s);
}

TEST_F(StreamAnalyzerTest, SequenceGapsAndRestarts) {
  const int64_t seqs[] = {0, 1, 2, 5, 6, 9, 0, 1};  // 2 + 2 lost, then a restart
  for (int i = 0; i < 8; ++i) add("SCAN", i, test::make_scan(i, seqs[i], 3));
  const ChannelSummary s = get("SCAN");
  EXPECT_EQ(s.seq_gaps, 4);
  EXPECT_EQ(s.seq_restarts, 1);
  EXPECT_TRUE(s.clean());  // loss is reported, but the log itself is intact
}

TEST_F(StreamAnalyzerTest, ChannelsAreKeptApart) {
  for (int i = 0; i < 3; ++i) add("A", 10 * i, test::make_pose(10 * i, i));
  for (int i = 0; i < 4; ++i) add("B", 10 * i + 5, test::make_imu(10 * i + 5, i));
  const auto all = a_.summary();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all.at("A").count, 3);
  EXPECT_EQ(all.at("B").count, 4);
  EXPECT_EQ(all.at("B").type, "traverse.imu_t");
  EXPECT_EQ(all.at("B").frames, std::set<std::string>{"imu"});
  EXPECT_EQ(all.at("A").seq_gaps + all.at("B").seq_gaps, 0);
}

}  // namespace
}  // namespace traverse::validate
