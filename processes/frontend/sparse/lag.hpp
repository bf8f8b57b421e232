// A two-phase frontend run one scan behind on a log subsampled by travel (MatcherConfig::
// sparse_lag), so that the scan after can still move a scan's pose. Where a scan fits a map that
// an earlier pass made otherwise (a door then open, that pass's drift) better at a wrong pose,
// the next scan usually lands right again, and the pair of steps shows it.
//
// Until the stream is known to be subsampled by travel (Measurement::subsampled_by_travel) each
// scan is measured and integrated at once. From then on, scan k is integrated tentatively and
// held; once scan k+1 has been measured, scan k is settled:
//   - if both were matched as sparse scans and scan k's pose lies outside sparse_lag_window_m /
//     _rad of the pose halfway between scans k-1 and k+1 (with wheel odometry: of where odometry's
//     step from scan k-1 puts it), scan k's integration is undone and its
//     points are matched again in that window around the halfway pose. Both poses are scored in
//     the map without scan k: evidence per point, minus the step prior of the steps into and out
//     of the pose (step_prior.hpp), minus sparse_lag_long_weight per point at 0.3 m beyond 1.25
//     times the log's usual step (90th percentile of the last 30 settled steps; a step that
//     wheel odometry measured, or a widened search found, longer than that: 1.25 times its
//     length; sparse/widen.hpp). The other pose
//     is taken if it scores sparse_lag_margin per point more; the pose not taken joins the
//     covariance as a second place the pose may be (the score spread of the two, weighted as the
//     wide search weighs its surface). Scan k is integrated where it settled, and if it moved,
//     scan k+1 is matched again from its own pose with the step from scan k's new one: the motion
//     model then derives its velocity and average step from the settled poses.
//   - otherwise scan k stays as integrated.
// Its result (with its own utime) is then the result of scan k+1's process() call; the first
// held scan's call returns kHeld, and finish() gives the last scan's pose.
#pragma once

#include <memory>
#include <optional>

#include "frontend.hpp"
#include "recent_values.hpp"
#include "two_phase.hpp"

namespace traverse::frontend {

class SparseLag final : public FrontendWrapper<TwoPhaseFrontend> {
 public:
  SparseLag(std::unique_ptr<TwoPhaseFrontend> frontend, const MatcherConfig& config);

  FrontendResult process(const Scan& scan) override;
  std::optional<FrontendResult> finish() override;
  void report(const CounterSink& sink) const override;

 private:
  // A scan integrated tentatively, and the pose its step starts from (the scan before's, settled).
  struct Held {
    Measurement measurement;
    Pose2 T_before;
  };
  // Settles the held scan given the next scan's measurement (none at the end of the stream),
  // matching `next` again if the held scan moved; returns the held scan's result.
  FrontendResult settle(Held held, Measurement* next);
  // The lag's score of the held scan at T (see the header) with the next scan, `next`, at T_next.
  double score(const Held& held, const Pose2& T, const Measurement& next, const Pose2& T_next) const;

  MatcherConfig config_;
  bool lagging_ = false;
  std::optional<Held> held_;
  static constexpr std::size_t kRecentSteps = 30;
  RecentValues<kRecentSteps> recent_steps_m_;  // lengths of the last settled steps [m]
  int64_t scans_revised_ = 0;                  // poses moved once the next scan was matched
};

}  // namespace traverse::frontend
