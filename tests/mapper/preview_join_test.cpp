// Listeners that ask for the mapper's preview while an answer to another is going out
// (PreviewResend::answer, docs/late-joining.md): they join it, it is never restarted.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "preview_corridor.hpp"
#include "preview_resend.hpp"

namespace traverse::mapper {
namespace {

using PointsByTime = std::map<int64_t, std::vector<std::array<int16_t, 3>>>;

// The points of everything `resend` has left to answer, by profile time.
PointsByTime drain(PreviewResend& resend) {
  PointsByTime out;
  while (resend.resending()) {
    for (const PreviewProfile& p : resend.next(50)) {
      auto& pts = out[p.utime];
      pts.insert(pts.end(), p.p_base_mm.begin(), p.p_base_mm.end());
    }
  }
  return out;
}

// Listeners that ask while an answer goes out join it instead of restarting it: it goes on to the
// newest profile, then round from the oldest to where the last one joined (a second round if one
// joins during the first). Each gets the whole store after asking, and a profile goes once per
// listener that needed it, at most: three for the part before the third listener joined, two after.
TEST(PreviewResend, ListenersWhoJoinAnAnswerUnderWayEachGetTheWholeStore) {
  int64_t max_bytes[1] = {0};
  const auto store = [&](bool more) {  // the same route, answered whole by a store of its own
    PreviewResend copy(0.05, 64 << 20);
    drive_corridor(0.0, 10.0, copy, max_bytes);
    if (more) drive_corridor(10.05, 12.0, copy, max_bytes);
    copy.answer();
    return drain(copy);
  };
  const PointsByTime kept_a = store(false), kept_b = store(true);
  PreviewResend resend(0.05, 64 << 20);  // no thinning
  drive_corridor(0.0, 10.0, resend, max_bytes);
  std::vector<int64_t> order;
  std::map<int64_t, std::size_t> after_a, after_b, after_c;  // points sent after each asked
  const auto send = [&](std::size_t calls) {
    for (std::size_t k = 0; k < calls && resend.resending(); ++k) {
      for (const PreviewProfile& p : resend.next(50)) {
        order.push_back(p.utime);
        after_a[p.utime] += p.p_base_mm.size();
        after_b[p.utime] += p.p_base_mm.size();
        after_c[p.utime] += p.p_base_mm.size();
      }
    }
  };
  const PreviewResend::Mark a = resend.answer();
  send(40);
  drive_corridor(10.05, 12.0, resend, max_bytes);  // more route, sent live, while it goes out
  after_b.clear();
  after_c.clear();
  const PreviewResend::Mark b = resend.answer();  // joins
  const int64_t b_at = order.back();
  EXPECT_FALSE(resend.went_round(a));
  // On past the newest profile and round, to before where the second joined.
  while (resend.resending() && !resend.went_round(a)) send(1);
  send(10);
  ASSERT_TRUE(resend.resending());
  EXPECT_TRUE(resend.went_round(a));
  EXPECT_FALSE(resend.went_round(b));
  after_c.clear();
  const PreviewResend::Mark c = resend.answer();  // joins in the second round
  const int64_t c_at = order.back();
  ASSERT_LT(c_at, b_at);
  send(100000);
  EXPECT_FALSE(resend.resending());
  EXPECT_TRUE(resend.went_round(b));
  EXPECT_TRUE(resend.went_round(c));

  for (const auto& [kept, after] :
       {std::pair{&kept_a, &after_a}, {&kept_b, &after_b}, {&kept_b, &after_c}}) {
    int missed = 0;
    for (const auto& [t, pts] : *kept) missed += (*after)[t] < pts.size();
    EXPECT_EQ(missed, 0);
  }
  // after_a: everything sent. The profile the third joined in went twice and the part of it
  // before the join a third time.
  int wrong = 0;
  for (const auto& [t, pts] : kept_b) {
    const std::size_t n = pts.size(), got = after_a[t];
    wrong += t == c_at ? got < 2 * n || got > 3 * n : got != (t < c_at ? 3u : 2u) * n;
  }
  EXPECT_EQ(wrong, 0);
  // Never restarted: in time order but for the two rounds, each back to the oldest profile.
  std::vector<std::size_t> rounds;
  for (std::size_t i = 1; i < order.size(); ++i) {
    if (order[i] < order[i - 1]) rounds.push_back(i);
  }
  ASSERT_EQ(rounds.size(), 2u);
  for (std::size_t i : rounds) {
    EXPECT_EQ(order[i - 1], kept_b.rbegin()->first);
    EXPECT_EQ(order[i], kept_b.begin()->first);
  }
  EXPECT_LE(order.back(), c_at);
}

// Viewers opened one after another while the answer goes out, for longer than the store takes
// to send, each have the whole store within one store's worth of sending after asking (restarted
// at each, the answer would not reach the end of the store until they stopped coming), and the
// answer ends one round after the last.
TEST(PreviewResend, ListenersJoiningOneAfterAnotherEachHaveTheStoreWithinOneRound) {
  int64_t max_bytes[1] = {0};
  PreviewResend resend(0.05, 64 << 20);  // no thinning
  drive_corridor(0.0, 10.0, resend, max_bytes);
  resend.answer();
  const PointsByTime kept = drain(resend);
  std::size_t store = 0;
  for (const auto& [t, pts] : kept) store += pts.size();
  struct Listener {
    PreviewResend::Mark mark;
    std::size_t asked_at = 0;                 // points sent before it asked
    std::size_t had_all_at = 0;               // ... before the answer went round for it (0: not)
    std::map<int64_t, std::size_t> got = {};  // points per profile time since it asked
  };
  std::vector<Listener> listeners{{resend.answer(), 0}};
  std::size_t sent = 0;
  for (int calls = 0; resend.resending(); ++calls) {
    for (const PreviewProfile& p : resend.next(50)) {
      sent += p.p_base_mm.size();
      for (Listener& l : listeners) l.got[p.utime] += p.p_base_mm.size();
    }
    for (Listener& l : listeners) {
      if (l.had_all_at == 0 && resend.went_round(l.mark)) l.had_all_at = sent;
    }
    if (calls % 40 == 39 && listeners.size() < 40) listeners.push_back({resend.answer(), sent});
  }
  RecordProperty("store_points", std::to_string(store));
  RecordProperty("sent_points", std::to_string(sent));
  ASSERT_EQ(listeners.size(), 40u);
  ASSERT_GT(listeners.back().asked_at, 2 * store);  // the stream outlasted two stores
  EXPECT_LE(sent - listeners.back().asked_at, store);
  int late = 0, missed = 0;
  for (const Listener& l : listeners) {
    // Checked between calls: up to one call (50 points) past the round.
    late += l.had_all_at == 0 || l.had_all_at - l.asked_at > store + 50;
    for (const auto& [t, pts] : kept) missed += l.got.count(t) == 0 || l.got.at(t) < pts.size();
  }
  EXPECT_EQ(late, 0);
  EXPECT_EQ(missed, 0);
}

// A listener that joins before thinning passes (the store coarsened under the answer) gets every
// point still kept of what was stored when it asked.
TEST(PreviewResend, AListenerWhoJoinsGetsWhatIsKeptThroughThinning) {
  PreviewResend resend(0.05, 64 << 10);
  int64_t max_bytes[1] = {0};
  drive_corridor(0.0, 20.0, resend, max_bytes);
  const int64_t compactions = resend.counters().compactions;
  resend.answer();
  for (int k = 0; k < 20; ++k) resend.next(50);
  const PreviewResend::Mark b = resend.answer();
  const int64_t asked_at =
      kCorridorT0 + 401 * kCorridorDt;  // [us] after the newest profile stored then
  PointsByTime after_b;
  for (const PreviewProfile& p : resend.next(50)) {
    after_b[p.utime].insert(after_b[p.utime].end(), p.p_base_mm.begin(), p.p_base_mm.end());
  }
  drive_corridor(20.05, 80.0, resend, max_bytes);  // more route: thinned, under way
  EXPECT_GT(resend.counters().compactions, compactions + 1);
  for (auto& [t, pts] : drain(resend)) {
    after_b[t].insert(after_b[t].end(), pts.begin(), pts.end());
  }
  EXPECT_TRUE(resend.went_round(b));
  resend.answer();
  const PointsByTime kept = drain(resend);
  int missed = 0;
  for (const auto& [t, pts] : kept) {
    if (t >= asked_at) break;  // sent live after it asked
    const auto it = after_b.find(t);
    for (const auto& p : pts) {
      missed += it == after_b.end() ||
                std::find(it->second.begin(), it->second.end(), p) == it->second.end();
    }
  }
  EXPECT_EQ(missed, 0);
  EXPECT_GT(kept.size(), 100u);
}

}  // namespace
}  // namespace traverse::mapper
