// Late joining for what the graph publishes incrementally (the densifier's segments, the
// annotator's annotations, the mapper's preview): a listener that starts after the graph has run
// for a while asks once for the whole state behind the channels it reads (resend_request_t on
// RESEND_REQUEST), and each producer answers for its own channel on <channel>_FULL with the same
// type, so the listeners that were there from the start never see a second copy.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "bus.hpp"

namespace traverse {

// Asks once for the whole state of `wanted` (one message for all of them). Subscribe to
// channels::full_channel(c) of each before asking: the answers may come at once.
void request_resend(Publisher& bus, const std::string& requester,
                    const std::vector<std::string>& wanted);

// Calls answer(requester) for every resend request that names `channel`. An empty `channel`
// (a producer configured not to publish it) answers nothing.
void answer_resend_requests(Bus& bus, const std::string& channel,
                            std::function<void(const std::string& requester)> answer);

}  // namespace traverse
