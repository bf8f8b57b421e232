// Late joining, the one mechanism of the graph: what a process publishes incrementally (the
// backend's key poses and edges, the densifier's segments, the annotator's annotations, the
// mapper's preview) cannot be rebuilt by a listener that starts after it, or that lost a message.
// Such a listener asks once for the whole state behind the channels it reads (resend_request_t on
// RESEND_REQUEST, one message naming every channel wanted), and each producer answers for its own
// channels on <channel>_FULL with the same type, so the listeners that were there from the start
// never see a second copy. Who asks: the annotator (KEY_POSES, POSE_GRAPH_EDGES), the mapper
// (ANNOTATIONS), the viewer (CLOUD_PREVIEW, DENSE_SEGMENTS, ANNOTATIONS).
//
// Several processes ask on the one channel, so its sequence numbers interleave: the bus's
// per-channel loss count would see gaps that are no loss. The answering side therefore reads the
// requests itself (same layout checks as the bus) and keeps a sequence number per requester: a
// request that is no newer than the last one heard from its requester (a datagram delivered twice)
// is counted and dropped, as is one that does not decode.
//
// Answers are paced by data time (ResendPacing): an answer is a channel's whole state, and every
// process on the multicast bus receives it, so a requester that asks in a loop must not make the
// producer send it again and again. At most one answer per channel per `resend.pace_s` of the
// producer's data time (its config's, resend_config.hpp; so a replay answers as the live run did),
// per channel or per requester (ResendPacing::Scope); a request inside that stretch, or one from a
// requester whose answer is still going out (the mapper's goes out over seconds), is counted and
// dropped.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "bus.hpp"
#include "resend_config.hpp"

namespace traverse {

// Asks once for the whole state of `wanted` (one message for all of them; empty names are left
// out); `utime` [us] is the newest data time the requester holds (0: none). Subscribe to
// channels::full_channel(c) of each before asking: the answers may come at once. The request
// names `requester` and this process's id, so a process restarted under the same name is a new
// requester.
void request_resend(Publisher& bus, const std::string& requester,
                    const std::vector<std::string>& wanted, int64_t utime = 0);

struct ResendRequest {
  std::string requester;
  int64_t utime = 0;               // [us] newest data time the requester holds (0: none)
  std::vector<std::string> named;  // the answerer's channels that it names, in its order
};

struct ResendPacing {
  // [us] of data time between two answers (ResendConfig::pace_us()); 0 (or no data_time): no
  // stretch, every request answered but for `answering` below
  int64_t min_us = ResendConfig{}.pace_us();
  std::function<int64_t()> data_time;  // [us] the producer's newest data time
  // Whose answer starts the stretch. kChannel: any requester's; the one answer goes to every
  // listener (the backend: its listener asks again whenever something is still missing).
  // kRequester: the same requester's; a requester not answered yet is answered, since it may not
  // have been listening when the last answer went (the densifier and the annotator: their
  // listeners, the viewer and the mapper, ask once, when they start).
  enum class Scope { kChannel, kRequester } scope = Scope::kRequester;
  // For an answer that goes out over time (the mapper's, paced by bytes: seconds for a whole
  // store): true while an answer that `requester` will get whole is still going out. Its request
  // is then paced whatever the data time: answered, it would make the answer go round once more
  // for what the requester is being sent anyway. Empty: every answer goes out at once.
  std::function<bool(const std::string& requester)> answering = nullptr;
};

// Answers the requests that name any of `channels` (empty names: channels not published, never
// answered), paced by `pacing`: the answer function gets the named channels outside their stretch
// and returns whether it answered (a producer may decline: the backend with an empty graph); a
// declined request starts no stretch.
class ResendAnswerer {
 public:
  using Answer = std::function<bool(const ResendRequest& request)>;
  ResendAnswerer(Bus& bus, std::vector<std::string> channels, Answer answer,
                 ResendPacing pacing = {});
  ~ResendAnswerer();
  ResendAnswerer(const ResendAnswerer&) = delete;
  ResendAnswerer& operator=(const ResendAnswerer&) = delete;

  struct Counters {
    int64_t requests = 0;  // well-formed, new, naming one of the channels
    int64_t answers = 0;   // of those, answered
    int64_t paced = 0;     // of those, inside its stretch (or its answer going out): dropped
    int64_t repeated = 0;  // not newer than the last from the same requester: dropped
    int64_t rejected = 0;  // did not decode: dropped
  };
  const Counters& counters() const { return counters_; }
  // resend_requests, resend_answers, resend_requests_paced, resend_requests_repeated,
  // resend_requests_rejected.
  void report(const std::function<void(const std::string& name, double value)>& sink) const;

 private:
  void on_request(const uint8_t* data, int size);

  Bus& bus_;
  std::vector<std::string> channels_;
  Answer answer_;
  ResendPacing pacing_;
  Bus::Handle subscription_ = nullptr;
  std::map<std::string, int64_t> last_seq_;     // by requester
  std::map<std::string, int64_t> last_answer_;  // [us] data time, by channel (and requester)
  Counters counters_;
};

}  // namespace traverse
