// A frontend in two phases, as kiss-icp's register, then update the map: measure() matches a
// scan against the map from the motion model's prediction and changes nothing (but its
// counters); integrate() takes the measurement into the motion model and, when due, the map. The
// wrappers of sparse/ work between the two: they hold a measurement, match it again somewhere
// else, compare, and integrate what they settle on. Integrations after begin_tentative() can be
// undone exactly by rollback() (map and motion alike), so that a wrapper can take a scan back
// out and integrate it elsewhere, and every state derived from its pose follows.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "frontend.hpp"

namespace traverse::frontend {

// A scan registered against the map, not yet integrated.
struct Measurement {
  FrontendResult result;
  std::vector<Eigen::Vector2d> points;          // valid points, base frame, motion compensated
  std::vector<Eigen::Vector2d> points_matched;  // the subset matched against the map
  // The stream's recent scans came further apart than a scanner's period (its median interval
  // above MatcherConfig::wide_search_gap_us): a log subsampled by travel.
  bool subsampled_by_travel = false;
  // Wheel odometry's step from the pose before to this scan, where the prediction took it.
  std::optional<Pose2> odometry_step;
  // A step the data show is long: its length [m], where a search wider than the wide search's
  // window found the scan (sparse/widen.hpp). The lag does not count a step up to it as long.
  std::optional<double> long_step_m;
};

// A result the wide search matched as a sparse scan: what the wrappers of sparse/ work on.
inline bool matched_sparse(const FrontendResult& r) {
  return r.status == ScanStatus::kMatched && r.sparse;
}

// Where to match a measurement again: around T_centre, within +-linear_window_m in x and y and
// +-angular_window_rad, the step from T_from (the pose before) weighed by the step prior.
struct SearchArea {
  Pose2 T_centre;
  double linear_window_m = 0.0;
  double angular_window_rad = 0.0;
  Pose2 T_from;
};

class TwoPhaseFrontend : public FrontendBase {
 public:
  // Registers a scan against the map (status kMatched, kPredicted or kDropped).
  virtual Measurement measure(const Scan& scan) = 0;
  // Takes a measurement (kMatched or kPredicted) into the motion model and, when due, the map.
  virtual void integrate(Measurement& measurement) = 0;
  // The measurement matched again within `area` (its result's pose and covariance replaced).
  virtual Measurement rematch(const Measurement& measurement, const SearchArea& area) const = 0;
  // How well the measurement's matched points fit the map at T: mean evidence per point, -1 (all
  // on free cells) to 1 (all on occupied ones).
  virtual double evidence(const Measurement& measurement, const Pose2& T_map_base) const = 0;
  // The pose of the last scan integrated (the initial pose before the first).
  virtual Pose2 last_pose() const = 0;

  virtual void begin_tentative() = 0;
  virtual void rollback() = 0;  // undoes every integration since begin_tentative()
  virtual void commit() = 0;    // keeps them
};

// A Frontend wrapped around another frontend `Inner` (a Frontend or a TwoPhaseFrontend), which
// takes the samples and reports: what the wrappers below and in sparse/ are.
template <class Inner>
class FrontendWrapper : public Frontend {
 public:
  explicit FrontendWrapper(std::unique_ptr<Inner> inner) : inner_(std::move(inner)) {}
  bool add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) override {
    return inner_->add_imu(utime, angular_velocity_imu);
  }
  bool add_odometry(const OdometrySample& odometry) override {
    return inner_->add_odometry(odometry);
  }
  std::size_t map_bytes() const override { return inner_->map_bytes(); }
  void report(const CounterSink& sink) const override { inner_->report(sink); }

 protected:
  std::unique_ptr<Inner> inner_;
};

// A two-phase frontend as a Frontend: each scan measured and integrated at once.
class MeasureAndIntegrate final : public FrontendWrapper<TwoPhaseFrontend> {
 public:
  using FrontendWrapper::FrontendWrapper;
  FrontendResult process(const Scan& scan) override {
    Measurement m = inner_->measure(scan);
    if (m.result.has_pose()) inner_->integrate(m);
    return m.result;
  }
  std::optional<FrontendResult> finish() override { return std::nullopt; }
};

}  // namespace traverse::frontend
