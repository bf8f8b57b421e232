// Fuzz target: every path a message's bytes take -- the typed subscription of every process (the
// bus, for every message type), the type registry (traverse-validate, the evaluator) and the
// monitor's status decode. A message whose fingerprint is no known type is made one: its first
// byte picks the type whose fingerprint replaces its first 8 bytes. Invariant: bytes the layout
// walk accepts decode completely (the walk is never looser than the decoder).
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "bus.hpp"
#include "message_checks.hpp"
#include "monitor_node.hpp"
#include "traverse/dense_segments_t.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/process_status_t.hpp"
#include "type_registry.hpp"

namespace {

struct Subscribers {
  traverse::Bus bus{"memq://"};
  traverse::MonitorNode monitor{bus, traverse::MonitorConfig{}};
  Subscribers() {
    using namespace traverse;
    bus.subscribe<planar_scan_t>("traverse.planar_scan_t", [](const planar_scan_t&) {});
    bus.subscribe<imu_t>("traverse.imu_t", [](const imu_t&) {});
    bus.subscribe<pose2d_t>("traverse.pose2d_t", [](const pose2d_t&) {});
    bus.subscribe<odometry_t>("traverse.odometry_t", [](const odometry_t&) {});
    bus.subscribe<key_poses_t>("traverse.key_poses_t", [](const key_poses_t&) {});
    bus.subscribe<dense_segments_t>("traverse.dense_segments_t", [](const dense_segments_t&) {});
    bus.subscribe<process_status_t>("STATUS_FUZZ", [](const process_status_t&) {});
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static Subscribers subscribers;
  using namespace traverse;
  if (size < 1) return 0;
  std::vector<uint8_t> msg(data, data + size);
  const TypeInfo* type = type_of_fingerprint(msg.data(), msg.size());
  if (!type) {
    const auto& types = all_types();
    type = &types[data[0] % types.size()];
    if (msg.size() < 8) msg.resize(8);
    for (int i = 0; i < 8; ++i) msg[i] = static_cast<uint8_t>(type->fingerprint >> (56 - 8 * i));
  }
  const WalkResult walk = walk_message(*type->layout, msg.data(), msg.size());
  const Inspection r = type->inspect(msg.data(), static_cast<int>(msg.size()), {});
  if (walk.ok() && r.verdict == MessageVerdict::kMalformed) std::abort();
  if (!walk.ok() && r.verdict != MessageVerdict::kMalformed) std::abort();
  if ((find_type(msg.data(), msg.size()) != nullptr) != walk.ok()) std::abort();

  const std::string channel =
      type->name == "traverse.process_status_t" ? "STATUS_FUZZ" : type->name;
  subscribers.bus.lcm().publish(channel, msg.data(), static_cast<unsigned>(msg.size()));
  while (subscribers.bus.lcm().handleTimeout(0) > 0) {
  }
  return 0;
}
