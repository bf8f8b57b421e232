// The platform's true motion: a cart pushed along a route of waypoints. Between waypoints it
// drives straight with a trapezoidal speed profile (accelerate, cruise, brake to a stop); at each
// waypoint it turns on the spot with a trapezoidal yaw-rate profile; it may pause. On top of the
// nominal motion the cart vibrates: each vibration component is a sinusoid whose phase advances
// with the distance rolled by the wheels (wheel out-of-roundness, floor tiles), so its frequency
// follows the speed and it dies out when the cart stands still. The ground truth is the nominal
// pose composed with the vibration, evaluated exactly at any time.
// With the realistic profile's motion effect the cart is pushed instead (pushed_path.hpp): corners
// are driven as arcs and only stops and reversals are turned on the spot; with its floor effect
// the cart also rises, pitches and rolls on the floor (floor.hpp), giving a 6-DoF pose.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "effects.hpp"
#include "floor.hpp"
#include "pushed_path.hpp"
#include "rng.hpp"
#include "se2.hpp"

namespace traverse::sim {

// Extra waypoints driven only with a world layer (a detour into a part of the world that only
// that layer builds): inserted after waypoint `after`.
struct DetourSpec {
  std::string layer = "realistic";
  int after = 0;
  std::vector<std::vector<double>> waypoints;  // [m] [[x, y], ...] in world
  template <class V>
  void visit(V& v) {
    v("layer", layer);
    v("after", after);
    v("waypoints", waypoints);
  }
};

// configs/routes/*.yaml
struct RouteSpec {
  std::string world;                                // world name, must match the world file's name
  std::string horizontal_scanner = "focus3d_120s";  // rig model: focus3d_120s or focus3d_x330
  double speed_mps = 0.5;                           // [m/s] cruise speed on straight legs
  std::vector<std::vector<double>> waypoints;       // [m] [[x, y], ...] in world, 2+ points
  double start_heading_rad = 1e9;  // [rad] initial heading; default: towards waypoint 1
  double start_pause_s = 2.0;      // [s] standing still before moving (IMU settles)
  double end_pause_s = 2.0;        // [s] standing still at the end
  std::vector<int> stop_at;        // waypoint indices where the cart also pauses
  double stop_s = 3.0;             // [s] length of those pauses
  std::vector<DetourSpec> detours;
  template <class V>
  void visit(V& v) {
    v("world", world);
    v("horizontal_scanner", horizontal_scanner);
    v("speed_mps", speed_mps);
    v("waypoints", waypoints);
    v("start_heading_rad", start_heading_rad);
    v("start_pause_s", start_pause_s);
    v("end_pause_s", end_pause_s);
    v("stop_at", stop_at);
    v("stop_s", stop_s);
    v("detours", detours);
  }
};

// A route's waypoints with the detours of the named layers, and whether the cart pauses there.
struct Waypoint {
  Eigen::Vector2d p;
  bool stop = false;
};
std::vector<Waypoint> expand_route(const RouteSpec& route, const std::vector<std::string>& layers);

// One vibration component, added in the base frame.
struct VibrationSpec {
  std::string axis = "y";     // x (along), y (across) [m] or yaw [rad]
  double amplitude = 0.001;   // [m] or [rad] at reference speed and above
  double wavelength_m = 0.6;  // [m] of wheel travel per cycle
  template <class V>
  void visit(V& v) {
    v("axis", axis);
    v("amplitude", amplitude);
    v("wavelength_m", wavelength_m);
  }
};

struct PlatformConfig {
  double accel_mps2 = 0.4;        // [m/s^2] speeding up and braking on straight legs
  double yaw_rate_radps = 0.6;    // [rad/s] turning on the spot
  double yaw_accel_radps2 = 0.8;  // [rad/s^2]
  double half_track_m = 0.25;     // [m] wheel distance from the centre (wheel travel in turns)
  double vibration_ref_speed_mps =
      0.3;  // [m/s] wheel speed at which vibration is at full amplitude
  std::vector<VibrationSpec> vibration = {
      {"y", 0.002, 0.63},    // 2 mm sway per wheel turn (0.2 m wheel, slightly out of round)
      {"yaw", 0.002, 0.63},  // 2 mrad yaw wobble per wheel turn
      {"x", 0.001, 0.30},    // 1 mm surge on 0.3 m floor tile joints
      {"y", 0.0005, 0.05},   // 0.5 mm chatter on floor roughness (10 Hz at 0.5 m/s)
      {"yaw", 0.0005, 0.05}};
  template <class V>
  void visit(V& v) {
    v("accel_mps2", accel_mps2);
    v("yaw_rate_radps", yaw_rate_radps);
    v("yaw_accel_radps2", yaw_accel_radps2);
    v("half_track_m", half_track_m);
    v("vibration_ref_speed_mps", vibration_ref_speed_mps);
    v("vibration", vibration);
  }
};

class Trajectory {
 public:
  // Throws std::runtime_error for an unusable route (fewer than 2 waypoints, bad speed).
  // `rng` draws the vibration phases (and the pushed cart's speed and weave). `effects` selects
  // the motion (pushed or stop-and-turn) and the detours of its world layers. A pushed cart is
  // set down turned by `start_yaw_rad` from the route's start heading (draw_start_yaw) and rolls
  // back onto its first leg over motion.start_settle_m.
  Trajectory(const RouteSpec& route, const PlatformConfig& platform, Rng& rng,
             const Effects& effects = Effects{}.ideal(), double start_yaw_rad = 0.0);

  double duration_s() const { return segments_.empty() ? 0.0 : segments_.back().t1; }
  double length_m() const { return length_m_; }  // [m] driven on straight legs
  double start_yaw_rad() const { return start_yaw_rad_; }  // [rad] as set down (constructor)

  // True pose T_world_base at t [s] since the start (clamped to [0, duration]).
  Pose2 pose(double t) const;
  // Nominal pose without vibration.
  Pose2 nominal_pose(double t) const;
  // [m/s] nominal speed of the cart's centre, and [m] wheel travel so far.
  double nominal_speed(double t) const { return nominal_state(t).speed; }

  // The floor the wheels roll on (none: a plane floor, the cart stays level).
  void set_floor(std::shared_ptr<const FloorModel> floor) { floor_ = std::move(floor); }
  // True pose T_world_base in 3D: the planar pose, lifted and tilted by the floor.
  Eigen::Isometry3d pose3(double t) const;
  // The same from a planar pose.
  Eigen::Isometry3d lift(const Pose2& T_world_base) const;

 private:
  enum class Kind { kPause, kLine, kTurn, kRun };
  struct Segment {
    Kind kind;
    double t0, t1;       // [s]
    Pose2 start;         // nominal pose at t0
    double amount;       // [m] length (line) or [rad] signed angle (turn)
    double vmax, accel;  // [m/s, m/s^2] or [rad/s, rad/s^2]
    double dist0;        // [m] wheel travel before t0
    int run = -1;        // index into runs_ (kRun)
  };
  struct State {
    Pose2 pose;
    double dist;         // [m] wheel travel
    double wheel_speed;  // [m/s]
    double speed = 0.0;  // [m/s] of the centre
  };
  State nominal_state(double t) const;
  void add(Kind kind, const Pose2& start, double amount, double vmax, double accel);
  // Adds the start pause, the cart turned by yaw [rad] from the route's start heading; returns
  // the starting pose.
  Pose2 start(const RouteSpec& route, const std::vector<Waypoint>& wp, double yaw = 0.0);
  void plan_stop_and_turn(const RouteSpec& route, const std::vector<Waypoint>& wp);
  void plan_pushed(const RouteSpec& route, const std::vector<Waypoint>& wp,
                   const MotionEffect& motion, Rng& rng);
  void add_run(PushedRun run, const Pose2& start);

  std::vector<PushedRun> runs_;
  std::shared_ptr<const FloorModel> floor_;
  std::vector<Segment> segments_;
  PlatformConfig platform_;
  std::vector<double> phases_;
  std::vector<int> axes_;  // 0 x, 1 y, 2 yaw per vibration component
  double length_m_ = 0.0;
  double dist_ = 0.0;
  double start_yaw_rad_ = 0.0;
};

// The yaw [rad] a pushed cart is set down with against its route's start heading: magnitude
// uniform in [motion.start_yaw_min_rad, start_yaw_max_rad], random sign; 0 with motion off.
double draw_start_yaw(const MotionEffect& motion, Rng rng);

// Trapezoidal profile over `amount` (>= 0) with top rate vmax and acceleration a: duration and
// the travelled amount and rate at time tau.
double trapezoid_duration(double amount, double vmax, double a);
void trapezoid_at(double amount, double vmax, double a, double tau, double& s, double& v);

}  // namespace traverse::sim
