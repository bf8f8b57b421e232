#include "lcm_log.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "publisher.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse {
namespace {

namespace fs = std::filesystem;

class LcmLogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = fs::temp_directory_path() /
            ("traverse_log_test_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".lcmlog");
    LogFilePublisher out(path_.string());
    for (int i = 0; i < 10; ++i) {
      pose2d_t p{};
      p.utime = 1000 * (i + 1);
      p.x = i;
      out.publish(i % 2 ? "A" : "B", p);
    }
  }
  void TearDown() override { fs::remove(path_); }

  std::vector<LogEvent> read_all(LogReader& r) {
    std::vector<LogEvent> evs;
    while (auto ev = r.next()) evs.push_back(*ev);
    return evs;
  }

  fs::path path_;
};

TEST_F(LcmLogTest, ReadsBackWhatWasWritten) {
  LogReader r(path_.string());
  const auto evs = read_all(r);
  ASSERT_EQ(evs.size(), 10u);
  EXPECT_TRUE(r.damage().empty());
  EXPECT_EQ(evs[3].channel, "A");
  EXPECT_EQ(evs[3].utime, 4000);
  pose2d_t p;
  ASSERT_EQ(p.decode(evs[3].data.data(), 0, static_cast<int>(evs[3].data.size())),
            static_cast<int>(evs[3].data.size()));
  EXPECT_DOUBLE_EQ(p.x, 3.0);
  EXPECT_EQ(p.seq, 1);  // second message on channel A
}

TEST_F(LcmLogTest, TruncatedLogIsReadUpToTheDamage) {
  std::vector<LogEvent> all;
  {
    LogReader r(path_.string());
    all = read_all(r);
  }
  // Cut in the middle of the 8th record's data.
  const uint64_t cut = all[7].offset + 40;
  fs::resize_file(path_, cut);
  LogReader r(path_.string());
  const auto evs = read_all(r);
  EXPECT_EQ(evs.size(), 7u);
  ASSERT_EQ(r.damage().size(), 1u);
  EXPECT_EQ(r.damage()[0].offset, all[7].offset);
  EXPECT_NE(r.damage()[0].what.find("truncated"), std::string::npos);
  EXPECT_EQ(r.damage()[0].skipped_bytes, cut - all[7].offset);
}

TEST_F(LcmLogTest, CorruptHeaderIsSkippedAndReadingResumes) {
  std::vector<LogEvent> all;
  {
    LogReader r(path_.string());
    all = read_all(r);
  }
  {
    std::fstream f(path_, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(all[4].offset));
    f.put('\x00');  // break the sync word of record 5
  }
  LogReader r(path_.string());
  const auto evs = read_all(r);
  EXPECT_EQ(evs.size(), 9u);
  ASSERT_EQ(r.damage().size(), 1u);
  EXPECT_EQ(r.damage()[0].offset, all[4].offset);
  EXPECT_EQ(r.damage()[0].what, "bad sync word");
  EXPECT_EQ(r.damage()[0].skipped_bytes, all[5].offset - all[4].offset);
}

// Sets the data length field of the record at `offset` to its value plus `delta`.
void change_data_length(const fs::path& path, uint64_t offset, int delta) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(static_cast<std::streamoff>(offset + 24));
  unsigned char b[4];
  f.read(reinterpret_cast<char*>(b), 4);
  uint32_t len = (uint32_t{b[0]} << 24) | (uint32_t{b[1]} << 16) | (uint32_t{b[2]} << 8) | b[3];
  len += static_cast<uint32_t>(delta);
  for (int i = 0; i < 4; ++i) b[i] = static_cast<unsigned char>(len >> (24 - 8 * i));
  f.seekp(static_cast<std::streamoff>(offset + 24));
  f.write(reinterpret_cast<char*>(b), 4);
}

TEST_F(LcmLogTest, RecordLengthCorruptionIsReportedWhereItIs) {
  std::vector<LogEvent> all;
  {
    LogReader r(path_.string());
    all = read_all(r);
  }
  for (int delta : {+10, -10, +100000}) {
    SetUp();
    change_data_length(path_, all[4].offset, delta);
    LogReader r(path_.string());
    const auto evs = read_all(r);
    EXPECT_EQ(evs.size(), 9u) << delta;  // record 5 alone is lost
    ASSERT_EQ(r.damage().size(), 1u) << delta;
    EXPECT_EQ(r.damage()[0].offset, all[4].offset) << delta << ": " << r.damage()[0].what;
    EXPECT_NE(r.damage()[0].what.find("record length"), std::string::npos) << r.damage()[0].what;
    EXPECT_EQ(r.damage()[0].skipped_bytes, all[5].offset - all[4].offset) << delta;
    EXPECT_EQ(evs[4].offset, all[5].offset);
  }
}

TEST(LcmLog, MissingFileThrows) {
  EXPECT_THROW(LogReader("/nonexistent/x.lcmlog"), std::runtime_error);
}

}  // namespace
}  // namespace traverse
