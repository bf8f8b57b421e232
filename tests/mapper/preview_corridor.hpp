// A corridor driven through for the tests of what the mapper keeps for a late viewer
// (preview_resend.hpp): preview_test.cpp and preview_join_test.cpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "preview.hpp"
#include "preview_resend.hpp"

namespace traverse::mapper {

inline constexpr int64_t kCorridorT0 = 1'700'000'000'000'000;  // [us] the first profile's time
inline constexpr int64_t kCorridorDt = 33'000;                 // [us] between profiles

// A corridor 3 m wide and 2.5 m high, driven straight along x for `length_m`: each profile is the
// ring of walls, floor and ceiling 0.4 m ahead of the cart, every 2 cm, one profile per 5 cm of
// travel (so each brings one new slice of cells, as a first pass through a building does), from
// `from_m` to `to_m` at 1.5 m/s. The preview's groups go into `resend` as the mapper node does;
// returns the points sent live.
inline int64_t drive_corridor(double from_m, double to_m, PreviewResend& resend,
                              int64_t max_bytes_seen[1]) {
  CloudPreview preview({.channel = "CLOUD_PREVIEW", .cell_m = 0.05});
  int64_t sent = 0;
  for (int i = static_cast<int>(std::lround(from_m / 0.05)); 0.05 * i <= to_m; ++i) {
    const Pose2 T(0.05 * i, 0.0, 0.0);
    const float x = static_cast<float>(T.x() + 0.4);
    std::vector<Eigen::Vector3f> ring;
    for (float y = -1.5f; y <= 1.5f; y += 0.02f) {
      ring.emplace_back(x, y, 0.0f);
      ring.emplace_back(x, y, 2.5f);
    }
    for (float z = 0.0f; z <= 2.5f; z += 0.02f) {
      ring.emplace_back(x, -1.5f, z);
      ring.emplace_back(x, 1.5f, z);
    }
    preview.add(kCorridorT0 + i * kCorridorDt, T, ring);
    for (const auto& group : preview.take()) {
      for (const PreviewProfile& p : group) {
        sent += static_cast<int64_t>(p.p_base_mm.size());
        resend.add(p);
        max_bytes_seen[0] = std::max(max_bytes_seen[0], resend.bytes());
      }
    }
    resend.poll();  // as the node does before each group (nothing without the background mode)
  }
  return sent;
}

}  // namespace traverse::mapper
