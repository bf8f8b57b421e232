// The frontend's trajectory in the pose graph.
//
// A scan-to-map frontend errs in two ways: each pose against its map, by about the covariance it
// publishes with the pose, independently from one pose to the next; and the map itself, which
// drifts slowly as the platform moves on. Relative poses between consecutive key poses share
// those errors (each pose's error enters two of them, with opposite signs), so a chain of
// consecutive frontend edges that each carry both poses' covariances grows as a random walk over
// every key step: on the CARMEN logs its heading allowance over 10 m is about three times the
// frontend's real heading error against the reference over 10 m (0.02 rad), and loop closures
// then bend the trajectory locally where the frontend was right.
//
// The drift model keeps both errors apart with one auxiliary vertex per key pose, the drifting
// frontend's pose M_k (where the frontend's map places key pose k):
//   M_{k-1} -> M_k  the frontend's relative motion, with the map's drift over that step: a random
//                   walk that reaches one pose's covariance after drift_length_m of travel (a turn
//                   counts as kTurnLeverM metres per radian);
//   M_k -> X_k      identity, with the covariance the frontend published for pose k.
// The relative pose of two key poses then has the covariance of both poses plus the drift over
// the travel between them, whatever the number of key steps in between.
#pragma once

#include <Eigen/Core>

#include "pose_graph.hpp"
#include "trajectory_prep.hpp"

namespace traverse::backend {

// [m/rad] a turn on the spot drifts the map as much as this much travel per radian.
constexpr double kTurnLeverM = 0.5;

// The covariance of a prepared pose's frontend error in its own frame (the frame of the error of
// an edge ending at it), m^2, m rad, rad^2: the published one (scaled), turned from the frontend's
// map into the prepared frame; `fallback` (in the pose's frame) when it carries none.
Eigen::Matrix3d frontend_pose_covariance(const PreparedPose& pose, double scale,
                                         const Eigen::Matrix3d& fallback);

// The edge M_a -> M_b of the drift model: the frontend's motion from a to b with the map's drift
// over it; ca, cb: the two poses' covariances (frontend_pose_covariance). The map drifts by the
// frontend's typical error, the mean of the two covariances. In a scanner's stream (both poses
// paced, PreparedPose::paced) one scan among hundreds hardly moves the map, so one ambiguous
// match (a sparse scan after a pause whose search found a second place it fits) moves its own
// pose and not the drift: a covariance more than ten times its neighbour's (by the position
// variances) enters the mean scaled down to ten times. In a log subsampled by travel each scan is
// much of the map where it lies, and an ambiguous one moves it: the mean as it is.
Edge drift_edge(int from, int to, const PreparedPose& a, const PreparedPose& b,
                const Eigen::Matrix3d& ca, const Eigen::Matrix3d& cb, double drift_length_m);

// The frontend's motion from a to b as one edge with both poses' covariances (without the drift
// model).
Edge motion_edge(int from, int to, const PreparedPose& a, const PreparedPose& b,
                 const Eigen::Matrix3d& ca, const Eigen::Matrix3d& cb);

// The frontend's motion from a to b as one edge between the key poses, with the covariance the
// drift model gives that relative pose: both poses' errors and the map's drift over the step
// (drift_length_m 0: no drift). What a consumer of the key poses alone gets (the published edges,
// backend_node.hpp): a chain of such edges leaves out that consecutive steps share a pose's
// error, so over many steps it allows more than the model.
Edge key_step_edge(int from, int to, const PreparedPose& a, const PreparedPose& b,
                   const Eigen::Matrix3d& ca, const Eigen::Matrix3d& cb, double drift_length_m);

}  // namespace traverse::backend
