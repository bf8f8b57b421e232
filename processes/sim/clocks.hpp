// Sensor clocks and calibration errors, drawn per run: what the processes are never told.
// - Each sensor stamps its messages with its own clock: stamp = true time + offset + drift x time
//   since the start + jitter. Jitter is drawn per message from a generator keyed by the message's
//   index (so a stamp does not depend on how streams interleave) and bounded at 2 sigma, so a
//   stream's stamps never go backwards at the rates simulated (jitter_s at most a quarter period).
// - The true extrinsics differ from what the rig file says by a small rotation and lever arm.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "effects.hpp"
#include "rig.hpp"
#include "rng.hpp"

namespace traverse::sim {

struct SensorClock {
  bool enabled = false;
  double offset_s = 0.0;  // [s]
  double drift = 0.0;     // [s/s] (ppm x 1e-6)
  double jitter_s = 0.0;  // [s] 1 sigma
  uint64_t seed = 0, stream = 0;

  static SensorClock draw(const ClockEffect& e, uint64_t seed, uint64_t stream) {
    SensorClock c;
    if (!e.enabled) return c;
    Rng rng(seed, stream);
    c.enabled = true;
    c.offset_s = rng.uniform(-e.offset_max_s, e.offset_max_s);
    c.drift =
        (rng.bernoulli(0.5) ? 1.0 : -1.0) * 1e-6 * rng.uniform(e.drift_min_ppm, e.drift_max_ppm);
    c.jitter_s = e.jitter_s;
    c.seed = seed;
    c.stream = stream;
    return c;
  }

  // [s] how far the clock runs ahead of true time `t_s` [s] after the start (no jitter).
  double error_s(double t_s) const { return offset_s + drift * t_s; }

  // [us] what the clock reads at true time `true_utime`, `t_s` [s] after the start (no jitter).
  int64_t reading(int64_t true_utime, double t_s) const {
    if (!enabled) return true_utime;
    return true_utime + std::llround(1e6 * error_s(t_s));
  }

  // [us] stamp of message k taken at true time `true_utime`, `t_s` [s] after the start.
  int64_t stamp(int64_t true_utime, double t_s, int64_t k) const {
    if (!enabled) return true_utime;
    Rng rng(seed, stream + 0x100000000ULL * static_cast<uint64_t>(k + 1));
    const double jitter = jitter_s * std::clamp(rng.normal(), -2.0, 2.0);
    return true_utime + std::llround(1e6 * (error_s(t_s) + jitter));
  }
};

// The true T_base_sensor: the nominal one turned by a yaw error of magnitude in [yaw_min,
// yaw_max] (random sign) and small roll and pitch errors, its origin moved by lever_arm_sigma per
// axis.
inline Extrinsic perturb_extrinsic(const Extrinsic& nominal, const CalibrationEffect& e, Rng& rng) {
  if (!e.enabled) return nominal;
  Extrinsic t = nominal;
  t.yaw += (rng.bernoulli(0.5) ? 1.0 : -1.0) * rng.uniform(e.yaw_min_rad, e.yaw_max_rad);
  t.roll += rng.normal(e.tilt_sigma_rad);
  t.pitch += rng.normal(e.tilt_sigma_rad);
  t.x += rng.normal(e.lever_arm_sigma_m);
  t.y += rng.normal(e.lever_arm_sigma_m);
  t.z += rng.normal(e.lever_arm_sigma_m);
  return t;
}

}  // namespace traverse::sim
