// Which LCM URL a process uses: --lcm-url, else LCM_DEFAULT_URL (said at start, never silently),
// else the loopback-only default.
#include <gtest/gtest.h>

#include "process.hpp"

namespace traverse {
namespace {

TEST(LcmUrl, CommandLineWinsThenEnvironmentThenDefault) {
  EXPECT_EQ(choose_lcm_url("", nullptr).url, kDefaultLcmUrl);
  EXPECT_EQ(choose_lcm_url("", nullptr).note, "");
  EXPECT_EQ(choose_lcm_url("", "").url, kDefaultLcmUrl);
  const LcmUrlChoice env = choose_lcm_url("", "udpm://239.255.76.67:7000?ttl=0");
  EXPECT_EQ(env.url, "udpm://239.255.76.67:7000?ttl=0");
  EXPECT_NE(env.note.find("from LCM_DEFAULT_URL"), std::string::npos) << env.note;
  const LcmUrlChoice cli = choose_lcm_url("memq://", "udpm://239.255.76.67:7000?ttl=1");
  EXPECT_EQ(cli.url, "memq://");
  EXPECT_EQ(cli.note, "");
}

TEST(LcmUrl, AUrlThatLeavesTheHostIsSaid) {
  // Before: LCM_DEFAULT_URL with ttl=1 replaced the ttl=0 default without a word.
  const LcmUrlChoice env = choose_lcm_url("", "udpm://239.255.76.67:7667?ttl=1");
  EXPECT_NE(env.note.find("ttl=1: messages leave this host"), std::string::npos) << env.note;
  const LcmUrlChoice cli = choose_lcm_url("udpm://239.255.76.67:7667?ttl=2&recv_buf_size=1", nullptr);
  EXPECT_NE(cli.note.find("ttl=2"), std::string::npos) << cli.note;
}

}  // namespace
}  // namespace traverse
