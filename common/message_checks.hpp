// What every consumer of a message gets checked before the message reaches it: its bytes hold
// what it claims (message_layout.hpp), and what it says can be right. A check here rejects only
// what cannot be right for any sensor or process -- a scan whose beams all point the same way
// (angle_step 0: the frontend drifted 2.1 m on such scans with a millimetre covariance), a
// non-finite pose or IMU rate -- never what is merely unusual.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "message_layout.hpp"
#include "traverse/imu_t.hpp"
#include "traverse/odometry_t.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"
#include "type_registry.hpp"

namespace traverse {

// Why a decoded message cannot be right, or nullopt.
std::optional<std::string> implausible(const planar_scan_t& m);
std::optional<std::string> implausible(const imu_t& m);
std::optional<std::string> implausible(const pose2d_t& m);
std::optional<std::string> implausible(const odometry_t& m);

// Walks `data` along T's layout, decodes it only if it holds what it claims and keeps to
// `limits`, then checks it for plausibility. `msg` is usable when the verdict is kGood.
template <class T>
Inspection decode_checked(const void* data, int size, const std::vector<ArrayLimit>& limits,
                          T& msg) {
  static const TypeInfo* const type = type_with_fingerprint(static_cast<uint64_t>(T::getHash()));
  Inspection r;
  if (!type || size < 0) {
    r.problem = "no layout for this type";
    return r;
  }
  const WalkResult walk = walk_message(*type->layout, static_cast<const uint8_t*>(data),
                                       static_cast<std::size_t>(size), limits);
  if (!walk.ok()) {
    r.verdict = walk.outcome == WalkResult::Outcome::kOverLimit ? MessageVerdict::kOverLimit
                                                                : MessageVerdict::kMalformed;
    r.problem = walk.problem;
    return r;
  }
  if (msg.decode(data, 0, size) != size) {
    r.problem = "does not decode as " + type->name;  // e.g. another type's fingerprint
    return r;
  }
  r.verdict = MessageVerdict::kGood;
  if constexpr (requires { implausible(msg); }) {
    if (auto why = implausible(msg)) {
      r.verdict = MessageVerdict::kImplausible;
      r.problem = std::move(*why);
    }
  }
  return r;
}

}  // namespace traverse
