// The graph's one late-joining mechanism (resend.hpp): a producer answers the requests that name
// its channels, once per request; a request delivered twice, or one that does not decode, is
// counted and dropped, and the producer keeps answering the next ones. Answers are paced by the
// producer's data time, per channel or per requester.
#include "resend.hpp"

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>

#include "channels.hpp"
#include "traverse/resend_request_t.hpp"

namespace traverse {
namespace {

struct Answered {
  std::vector<std::vector<std::string>> named;
  std::map<std::string, double> counters;
};

void handle_all(Bus& bus) {
  while (bus.lcm().handleTimeout(0) > 0) {
  }
}

std::vector<uint8_t> encoded(resend_request_t m) {
  m.n_channels = static_cast<int32_t>(m.channels.size());
  std::vector<uint8_t> buf(m.getEncodedSize());
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

TEST(LateJoinResend, AnswersTheChannelsARequestNamesOnce) {
  Bus bus("memq://");
  Answered a;
  ResendAnswerer answerer(bus, {"EDGES", "", "KEYS"}, [&](const ResendRequest& r) {
    a.named.push_back(r.named);
    return true;
  });
  request_resend(bus, "one", {"KEYS", "OTHER", "EDGES"}, 42);
  request_resend(bus, "two", {"OTHER"});  // for another producer: not counted here
  request_resend(bus, "three", {"KEYS"});
  handle_all(bus);
  ASSERT_EQ(a.named.size(), 2u);
  EXPECT_EQ(a.named[0], (std::vector<std::string>{"EDGES", "KEYS"}));  // in the answerer's order
  EXPECT_EQ(a.named[1], (std::vector<std::string>{"KEYS"}));
  EXPECT_EQ(answerer.counters().requests, 2);
  EXPECT_EQ(answerer.counters().answers, 2);
  EXPECT_EQ(answerer.counters().repeated, 0);
  EXPECT_EQ(answerer.counters().rejected, 0);
}

TEST(LateJoinResend, DropsARepeatedOrMalformedRequestAndKeepsAnswering) {
  Bus bus("memq://");
  int answers = 0;
  bool answer = false;  // a producer may decline (the backend inside its stretch)
  ResendAnswerer answerer(bus, {"KEYS"}, [&](const ResendRequest& r) {
    EXPECT_EQ(r.requester, "viewer/7");
    ++answers;
    return answer;
  });
  resend_request_t m{};
  m.requester = "viewer/7";
  m.seq = 3;
  m.channels = {"KEYS"};
  const std::vector<uint8_t> bytes = encoded(m);
  bus.lcm().publish(channels::kResendRequest, bytes.data(), static_cast<unsigned>(bytes.size()));
  // The same datagram again, then an older one of the same requester: no newer, dropped.
  bus.lcm().publish(channels::kResendRequest, bytes.data(), static_cast<unsigned>(bytes.size()));
  m.seq = 2;
  const std::vector<uint8_t> older = encoded(m);
  bus.lcm().publish(channels::kResendRequest, older.data(), static_cast<unsigned>(older.size()));
  // Cut short, and junk: rejected.
  bus.lcm().publish(channels::kResendRequest, bytes.data(),
                    static_cast<unsigned>(bytes.size() - 3));
  const uint8_t junk[5] = {1, 2, 3, 4, 5};
  bus.lcm().publish(channels::kResendRequest, junk, 5);
  handle_all(bus);
  EXPECT_EQ(answers, 1);
  EXPECT_EQ(answerer.counters().requests, 1);
  EXPECT_EQ(answerer.counters().answers, 0);
  EXPECT_EQ(answerer.counters().repeated, 2);
  EXPECT_EQ(answerer.counters().rejected, 2);
  // The requester's next request, and a restarted one (a new process id: a new requester).
  answer = true;
  m.seq = 4;
  const std::vector<uint8_t> next = encoded(m);
  bus.lcm().publish(channels::kResendRequest, next.data(), static_cast<unsigned>(next.size()));
  handle_all(bus);
  EXPECT_EQ(answers, 2);
  EXPECT_EQ(answerer.counters().answers, 1);
  std::map<std::string, double> counters;
  answerer.report([&](const std::string& k, double v) { counters[k] = v; });
  EXPECT_EQ(counters.at("resend_requests"), 2.0);
  EXPECT_EQ(counters.at("resend_answers"), 1.0);
  EXPECT_EQ(counters.at("resend_requests_repeated"), 2.0);
  EXPECT_EQ(counters.at("resend_requests_rejected"), 2.0);
}

TEST(LateJoinResend, ARestartedRequesterIsANewOne) {
  Bus bus("memq://");
  int answers = 0;
  ResendAnswerer answerer(bus, {"KEYS"}, [&](const ResendRequest&) { return ++answers > 0; });
  resend_request_t m{};
  m.seq = 0;
  m.channels = {"KEYS"};
  for (const char* who : {"mapper/100", "mapper/100", "mapper/101"}) {
    m.requester = who;
    const std::vector<uint8_t> bytes = encoded(m);
    bus.lcm().publish(channels::kResendRequest, bytes.data(), static_cast<unsigned>(bytes.size()));
  }
  handle_all(bus);
  EXPECT_EQ(answers, 2);
  EXPECT_EQ(answerer.counters().repeated, 1);
}

TEST(LateJoinResend, PacesAnswersByDataTimePerRequesterOrPerChannel) {
  Bus bus("memq://");
  int64_t now = 10'000'000;  // [us] the producers' data time
  bool decline = false;
  std::map<std::string, int> answers;  // by producer
  const auto answerer = [&](const std::string& channel, ResendPacing::Scope scope) {
    return std::make_unique<ResendAnswerer>(
        bus, std::vector<std::string>{channel},
        [&, channel](const ResendRequest&) {
          if (decline) return false;
          ++answers[channel];
          return true;
        },
        ResendPacing{.data_time = [&] { return now; }, .scope = scope});
  };
  const auto per_requester = answerer("SEGMENTS", ResendPacing::Scope::kRequester);
  const auto per_channel = answerer("KEYS", ResendPacing::Scope::kChannel);
  const auto ask = [&](const std::string& who) {
    request_resend(bus, who, {"SEGMENTS", "KEYS"});
    handle_all(bus);
  };
  decline = true;  // a declined request starts no stretch
  ask("a");
  decline = false;
  ask("a");
  ask("a");  // inside a's stretch on both
  ask("b");  // a new requester: answered per requester, not per channel
  EXPECT_EQ(answers["SEGMENTS"], 2);
  EXPECT_EQ(answers["KEYS"], 1);
  now += 4'999'999;
  ask("a");
  EXPECT_EQ(answers["SEGMENTS"], 2);
  EXPECT_EQ(answers["KEYS"], 1);
  now += 1;  // 5 s after the first answers
  ask("a");
  EXPECT_EQ(answers["SEGMENTS"], 3);
  EXPECT_EQ(answers["KEYS"], 2);
  EXPECT_EQ(per_requester->counters().requests, 6);
  EXPECT_EQ(per_requester->counters().paced, 2);
  EXPECT_EQ(per_channel->counters().paced, 3);
  EXPECT_EQ(per_channel->counters().answers, 2);
}

// An answer that goes out over time (the mapper's): a request from a requester it still goes to
// is paced, past its stretch too, and with no stretch at all; another requester is answered, and
// once the answer is out the first one is too.
TEST(LateJoinResend, ARequestWhileItsAnswerGoesOutIsPaced) {
  for (const int64_t min_us : {int64_t{1'000'000}, int64_t{0}}) {
    Bus bus("memq://");
    int64_t now = 0;       // [us] the producer's data time
    std::string going_to;  // the requester of the answer going out ("": none)
    int answers = 0;
    ResendAnswerer answerer(
        bus, {"PREVIEW"},
        [&](const ResendRequest& r) {
          going_to = r.requester;
          return ++answers > 0;
        },
        ResendPacing{.min_us = min_us,
                     .data_time = [&] { return now; },
                     .answering = [&](const std::string& who) { return who == going_to; }});
    const auto ask = [&](const std::string& who) {
      request_resend(bus, who, {"PREVIEW"});
      handle_all(bus);
    };
    ask("viewer");
    now += 2'000'000;  // past its stretch, its answer still going out
    ask("viewer");
    EXPECT_EQ(answers, 1) << min_us;
    ask("other");
    EXPECT_EQ(answers, 2) << min_us;
    going_to.clear();  // out
    ask("viewer");
    EXPECT_EQ(answers, 3) << min_us;
    EXPECT_EQ(answerer.counters().requests, 4) << min_us;
    EXPECT_EQ(answerer.counters().paced, 1) << min_us;
  }
}

// resend.pace_s of every producer's config: seconds in, microseconds out, 0 to an hour.
TEST(LateJoinResend, ThePaceIsAConfigKeyInSeconds) {
  ResendConfig c;
  EXPECT_EQ(c.pace_us(), 5'000'000);
  EXPECT_EQ(ResendPacing{}.min_us, c.pace_us());
  load_config_text("pace_s: 1.5\n", "resend.yaml", c);
  EXPECT_EQ(c.pace_us(), 1'500'000);
  EXPECT_FALSE(validate(c));
  c.pace_s = 0.0;  // every request answered
  EXPECT_FALSE(validate(c));
  for (const double bad : {-0.5, 3600.5}) {
    c.pace_s = bad;
    EXPECT_NE(validate(c).value_or("").find("'pace_s'"), std::string::npos) << bad;
  }
}

TEST(LateJoinResend, AProducerWithoutTheChannelAnswersNothing) {
  Bus bus("memq://");
  int answers = 0;
  ResendAnswerer answerer(bus, {""}, [&](const ResendRequest&) { return ++answers > 0; });
  request_resend(bus, "viewer", {"KEYS", ""});
  request_resend(bus, "viewer", {""});  // nothing wanted: not sent at all
  handle_all(bus);
  EXPECT_EQ(answers, 0);
  EXPECT_EQ(bus.stats().at(channels::kResendRequest).published, 1);
}

}  // namespace
}  // namespace traverse
