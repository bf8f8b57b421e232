// Sparse scans matched by several frontends at once (MatcherConfig::sparse_ensemble_members),
// each started at an initial pose offset from the others' by a fraction of a map cell and under a
// degree: on a sparse log the outcome of one frontend turns on where the grid's cells happen to
// fall, and the members mostly go wrong at different scans. Each scan's published pose is the
// previous published pose times the step most members agree on (vote.hpp), with the chosen
// member's covariance plus the spread of all members' steps. The first member starts at the
// configured initial pose and its counters are the ones reported. A scanner's stream (three
// results in a row that are not sparse) drops all members but the first, which then carries on
// alone.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "frontend.hpp"

namespace traverse::frontend {

class SparseEnsemble final : public Frontend {
 public:
  // A member starting at T_map_base_initial.
  using MakeMember = std::function<std::unique_ptr<Frontend>(const Pose2& T_map_base_initial)>;
  // `members` members, offset from T_map_base_initial by fractions of a cell of `cell_m`.
  SparseEnsemble(const MakeMember& make_member, const Pose2& T_map_base_initial, int members,
                 double cell_m);

  bool add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) override;
  bool add_odometry(const OdometrySample& odometry) override;
  FrontendResult process(const Scan& scan) override;
  std::optional<FrontendResult> finish() override;
  // The members' maps together.
  std::size_t map_bytes() const override;
  void report(const CounterSink& sink) const override;

 private:
  // Votes on the members' results for one scan (results[0] the first member's, which must have a
  // pose): the result to publish.
  FrontendResult vote(const std::vector<std::optional<FrontendResult>>& results);
  // Each member's pose from its result, where it gave one.
  void remember(const std::vector<std::optional<FrontendResult>>& results);

  std::vector<std::unique_ptr<Frontend>> members_;
  std::vector<Pose2> last_;  // the pose each member last gave, in its own map frame
  Pose2 T_published_last_;
  int not_sparse_in_a_row_ = 0;
  int64_t steps_disputed_ = 0;  // steps on which not every member agreed
  int64_t steps_outvoted_ = 0;  // ... on which the first member's own step lost the vote
};

}  // namespace traverse::frontend
