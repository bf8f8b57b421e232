// A process busy in one step for seconds keeps its status beating (marked busy); a process that
// is not busy sends only its own statuses.
#include "status_beat.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace traverse {
namespace {

int64_t now_us() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

TEST(StatusBeat, BeatsWhileTheMainThreadIsBusy) {
  const std::string url = "udpm://239.255.76.67:31398?ttl=0";
  lcm::LCM sender(url), receiver(url);
  ASSERT_TRUE(sender.good() && receiver.good());
  struct Heard {
    std::vector<process_status_t> statuses;
    void on(const lcm::ReceiveBuffer*, const std::string&, const process_status_t* st) {
      statuses.push_back(*st);
    }
  } heard;
  receiver.subscribe("STATUS_T", &Heard::on, &heard);
  std::atomic<bool> done{false};
  std::thread listening([&] {
    while (!done) receiver.handleTimeout(50);
  });
  StatusBeat beat(sender, "STATUS_T", [](process_status_t& st) { st.utime = now_us(); });
  process_status_t st{};
  st.process = "t";
  st.state = "running";
  st.utime = now_us();
  beat.start();
  beat.send(st);
  std::this_thread::sleep_for(std::chrono::milliseconds(4200));  // one step of 4.2 s
  st.utime = now_us();
  beat.send(st);
  std::this_thread::sleep_for(std::chrono::milliseconds(800));  // not busy: no beat
  beat.stop();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  done = true;
  listening.join();
  ASSERT_GE(heard.statuses.size(), 4u);
  int busy = 0;
  for (std::size_t i = 0; i < heard.statuses.size(); ++i) {
    EXPECT_EQ(heard.statuses[i].seq, static_cast<int64_t>(i));  // one count, no gap
    if (heard.statuses[i].state.rfind("busy", 0) == 0) ++busy;
    if (i > 0) {
      EXPECT_LT(heard.statuses[i].utime - heard.statuses[i - 1].utime, 2'000'000) << i;
    }
  }
  EXPECT_GE(busy, 2);
  EXPECT_EQ(heard.statuses.back().state, "running");
}

}  // namespace
}  // namespace traverse
