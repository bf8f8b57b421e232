// The `resend` keys of every process that answers a late listener (common/resend.hpp: the
// backend, the densifier, the annotator, the mapper): one struct, so the key has one name, one
// default and one check in every config. No LCM here: a stage's library config may hold it.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include "config.hpp"

// In a namespace of its own, as pose_config.hpp: validate() is found by argument-dependent
// look-up, and namespace traverse has a namespace named validate.
namespace traverse::configs {

struct ResendConfig {
  // [s] of the producer's data time between two answers on one channel (per channel or per
  // requester, as the producer's ResendPacing::Scope); 0: every request answered.
  double pace_s = 5.0;

  int64_t pace_us() const { return std::llround(pace_s * 1e6); }  // [us]

  template <class V>
  void visit(V& v) {
    v("pace_s", pace_s);
  }
};

// An hour at most: a longer stretch would keep a restarted listener waiting for a whole session.
inline std::optional<std::string> validate(const ResendConfig& c) {
  ConfigCheck check;
  check.in_range("pace_s", c.pace_s, 0.0, 3600.0);
  return check.problem();
}

}  // namespace traverse::configs

namespace traverse {
using configs::ResendConfig;
}  // namespace traverse
