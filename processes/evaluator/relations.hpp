// Scoring a trajectory by relations, the metric of Kümmerle et al., "On measuring the accuracy of
// SLAM algorithms", Autonomous Robots 27(4), 2009: the benchmark 2D SLAM systems are compared on.
//
// A relation (one line of a .relations file: `t1 t2 dx dy dz droll dpitch dyaw`) is the true pose
// of the scan stamped t2 in the frame of the scan stamped t1 (metres, radians), verified by hand;
// t1 and t2 are the scans' ipc timestamps exactly as the log prints them. For each relation the
// estimate's own relative pose d = T(t1)^-1 T(t2) is compared with the relation d*:
//   e = d* ⊖ d, i.e. (d*)^-1 d (Kümmerle's eq. 2),
//   translational error |t(e)| = |t(d) - t(d*)| (both in the frame of the t1 scan), in m;
//   rotational error |wrap(theta(d) - theta(d*))|, reported in degrees;
// and over all relations used: mean, standard deviation (sample, n - 1, as Cartographer's tool
// that produced the published figures) and maximum of both errors, and mean and standard deviation
// of their squares (m^2, deg^2), as in Kümmerle's tables. (Cartographer's tool composes the other
// way round, d (d*)^-1, whose translation also carries the rotational error times the relation's
// length.) Dz, droll and dpitch are zero in 2D and unused.
//
// Matching: the relation's stamps are read into microseconds exactly from their digits (as the
// CARMEN driver reads a scan's stamp, seconds_text.hpp), and each is matched to the estimate's
// pose at that time: a pose stamped within `time_tolerance_us` of it (the nearest; 0 by default,
// since the driver publishes a scan at its stamp and the frontend stamps its pose with the scan's
// last point, utime_last, the same instant for a CARMEN scan). A relation whose scan has no pose
// there is missing: nothing is interpolated, so a stage that skipped the scan (or published key
// poses only) is never credited with a pose it did not give. Figures are refused (the evaluation
// says so, the program exits non-zero) when fewer than `min_share` of the relations are used.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "se2.hpp"
#include "trajectory.hpp"

namespace traverse::evaluator {

struct Relation {
  int64_t t1_utime = 0;  // [us] stamp of the scan the relation is expressed in
  int64_t t2_utime = 0;  // [us] stamp of the other scan
  Pose2 T_1_2;           // true pose of scan 2 in the frame of scan 1: [m], [m], [rad]
  int64_t line = 0;      // line number in the file, from 1
};

struct RelationsFile {
  std::vector<Relation> relations;  // in file order
  int64_t lines = 0;
  int64_t malformed_count = 0;  // lines that are not 8 finite numbers (blank and '#' lines skipped)
  std::vector<int64_t> malformed_lines;  // the first 100
  std::string error;                     // the file could not be read; empty otherwise
};

// Reads a relations file; never throws.
RelationsFile read_relations(const std::string& path);

struct RelationsConfig {
  // [us] a pose this close to a relation's stamp is the scan's pose (the nearest is taken).
  int64_t time_tolerance_us = 0;
  // [0..1] fewer relations used than this share: no figures.
  double min_share = 0.8;
};

struct RelationCheck {
  Relation relation;
  bool has_t1 = false, has_t2 = false;  // a pose was found at each stamp
  Pose2 T_est_1_2;                      // the estimate's relative pose, when both were found
  double translation_error_m = 0.0;     // |t(d) - t(d*)|
  double rotation_error_rad = 0.0;      // |wrap(theta(d) - theta(d*))|
  bool used() const { return has_t1 && has_t2; }
};

struct Moments {
  double mean = 0.0;
  double sd = 0.0;  // sample standard deviation (n - 1); 0 for fewer than two values
  double max = 0.0;
};
Moments moments(const std::vector<double>& values);

struct RelationsEvaluation {
  std::vector<RelationCheck> checks;  // one per relation, in file order
  std::size_t relations = 0;
  std::size_t used = 0;
  std::size_t missing = 0;
  double share = 0.0;    // used / relations (0 without relations)
  bool refused = false;  // share below RelationsConfig::min_share (or no relation at all)
  Moments translation_m, translation_sq_m2, rotation_deg, rotation_sq_deg2;  // over used ones
};

// `estimate` in any order (repeated times keep their first pose).
RelationsEvaluation evaluate_relations(Trajectory estimate, const std::vector<Relation>& relations,
                                       const RelationsConfig& config);

}  // namespace traverse::evaluator
