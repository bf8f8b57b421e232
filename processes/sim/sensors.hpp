// Simulated sensors. A scanner sweep casts every beam from the pose the cart has at that beam's own
// measurement time (so a sweep taken while moving is skewed exactly as on the real device), follows
// it through glass and off mirrors, and turns the true range into a measurement with the error
// model of rig.hpp: detection falls off with range, darkness and grazing incidence; noise grows
// with range and darkness; a per-run offset and an incidence-dependent bias (the beam footprint
// spreads along a slanted surface) shift it. The IMU samples the true angular rate and specific
// force of its own point on the cart (numerical derivatives of the true trajectory) and adds
// turn-on bias, Gauss-Markov bias drift and white noise.
// With the realistic profile (ScanExtras, ImuSim's three_d): beams leave the cart's 6-DoF pose,
// meet people and movables at their own time, scatter in angle, read surfaces that are not planes
// and dark ones long, mix at depth jumps and come out quantised (beam_errors.hpp); every message is
// stamped by the sensor's own clock (clocks.hpp).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "beam_errors.hpp"
#include "clocks.hpp"
#include "effects.hpp"
#include "people.hpp"
#include "rig.hpp"
#include "rng.hpp"
#include "trajectory.hpp"
#include "world.hpp"

namespace traverse::sim {

// Converts between trajectory time [s since start] and message time [us].
struct Clock {
  int64_t start_utime = 0;
  double seconds(int64_t utime) const { return 1e-6 * static_cast<double>(utime - start_utime); }
  // Time of sample k of a stream at `rate_hz`, rounded to the microsecond.
  int64_t sample_utime(int64_t k, double rate_hz) const {
    return start_utime + static_cast<int64_t>(std::llround(1e6 * static_cast<double>(k) / rate_hz));
  }
};

struct ScanData {
  std::string frame;
  int64_t utime_first = 0, utime_last = 0;  // [us]
  float angle_first = 0, angle_step = 0;    // [rad] in `frame`
  float range_min = 0, range_max = 0;       // [m]
  std::vector<float> ranges;                // [m], 0 = no return
  std::vector<uint8_t> intensities;         // [0..255]
};

// The realistic profile's additions to a scanner (all off by default: the ideal profile).
struct ScanExtras {
  BeamEffects beams = Effects{}.ideal().beams;
  bool three_d = false;            // beams leave the cart's 6-DoF pose (Trajectory::pose3)
  const People* people = nullptr;  // people walking through the beams
  const SurfaceModel* surface = nullptr;
  SensorClock clock;          // the scanner's own clock
  uint64_t effects_seed = 0;  // generator of the beam effects' draws (own stream)
};

class ScannerSim {
 public:
  // `T_base_laser` is the true extrinsic (the rig file's, or that with this run's calibration
  // error).
  ScannerSim(const ScannerModel& model, const Extrinsic& T_base_laser, std::string frame,
             const World& world, const Trajectory& trajectory, const Clock& clock, Rng rng,
             const ScanExtras& extras = {});

  // [us] true time of sweep k's first beam, and the stamp its message carries.
  int64_t sweep_utime(int64_t k) const { return clock_.sample_utime(k, model_.rate_hz); }
  int64_t sweep_stamp(int64_t k) const {
    const int64_t u = sweep_utime(k);
    return extras_.clock.stamp(u, clock_.seconds(u), k);
  }
  // Sweep k (the next one; sweeps must be asked for in order, the noise stream advances).
  ScanData sweep(int64_t k);

  // One measurement of a beam from `origin` along unit `dir` (world) at `time_s` [s since the
  // start]: range [m] or 0.
  float measure(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, uint8_t& intensity,
                double time_s = 0.0);

  // [s] time from one beam to the next and the span of a sweep.
  double beam_period_s() const { return beam_period_s_; }
  // Beams changed by mixing in the last sweep (realistic profile).
  int last_mixed() const { return last_mixed_; }

 private:
  double noise_sigma(double range, double reflectivity, double cos_incidence) const;
  BeamReturn measure_beam(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                          uint8_t& intensity, double time_s);
  // Nearest hit of the world and the people cylinders gathered for this stretch of the sweep.
  std::optional<RayHit> cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max,
                             double time_s) const;
  void sweep_planar(ScanData& scan, double t0, double dt);
  void sweep_3d(ScanData& scan, double t0, double dt);
  void gather_people(double time_s, const Eigen::Vector3d& origin);
  Eigen::Vector3d beam_dir(int i);  // in base (planar) or laser (3D) frame, jittered

  ScannerModel model_;
  Eigen::Isometry3d T_base_laser_;
  std::string frame_;
  const World& world_;
  const Trajectory& trajectory_;
  Clock clock_;
  Rng rng_;
  double beam_period_s_ = 0.0;
  double rate_noise_factor_ = 1.0;
  double range_offset_m_ = 0.0;  // this run's systematic range error
  double cos_grazing_limit_ = 0.0;
  std::vector<Eigen::Vector3d> beam_dirs_laser_;  // unit beam directions in the laser frame
  ScanExtras extras_;
  Rng effects_rng_;
  std::vector<Eigen::Vector3d> beam_perp_;  // d(direction)/d(angle), same frame as the beams
  std::vector<BeamReturn> returns_;
  std::vector<Cylinder> dynamic_;  // people near the scanner now
  int last_mixed_ = 0;
};

struct ImuData {
  int64_t utime = 0;
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     // [rad/s] imu frame
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  // [m/s^2] specific force
};

class ImuSim {
 public:
  // `three_d`: the cart's 6-DoF pose (floor model); `clock`: the IMU's own clock.
  ImuSim(const ImuModel& model, const Extrinsic& T_base_imu, const Trajectory& trajectory,
         const Clock& clock, Rng rng, bool three_d = false, const SensorClock& own_clock = {});
  int64_t sample_utime(int64_t k) const { return clock_.sample_utime(k, model_.rate_hz); }
  int64_t sample_stamp(int64_t k) const {
    const int64_t u = sample_utime(k);
    return own_clock_.stamp(u, clock_.seconds(u), k);
  }
  // Sample k (in order).
  ImuData sample(int64_t k);
  // Noise-free angular rate and specific force at t [s] (imu frame).
  void truth(double t, Eigen::Vector3d& omega, Eigen::Vector3d& specific_force) const;

 private:
  ImuModel model_;
  Eigen::Isometry3d T_base_imu_;
  const Trajectory& trajectory_;
  Clock clock_;
  Rng rng_;
  Eigen::Vector3d gyro_bias0_, accel_bias0_, gyro_drift_, accel_drift_;
  bool three_d_ = false;
  SensorClock own_clock_;
};

}  // namespace traverse::sim
