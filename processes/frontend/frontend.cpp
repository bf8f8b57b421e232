#include "frontend.hpp"

#include <algorithm>
#include <cmath>

#include "calibration/calibrated_frontend.hpp"
#include "hector/hector_frontend.hpp"
#include "icp/icp_frontend.hpp"
#include "sparse/ensemble.hpp"
#include "sparse/lag.hpp"
#include "sparse/widen.hpp"
#include "two_phase.hpp"

namespace traverse::frontend {

namespace {

std::unique_ptr<Frontend> make_hector(const FrontendConfig& config) {
  // One Hector frontend starting at T_map_base_initial, one scan behind on a log subsampled by
  // travel when the config says so.
  const auto make_member = [config](const Pose2& T_map_base_initial) -> std::unique_ptr<Frontend> {
    FrontendConfig c = config;
    c.initial_pose = {.x_m = T_map_base_initial.x(),
                      .y_m = T_map_base_initial.y(),
                      .theta_rad = T_map_base_initial.theta()};
    std::unique_ptr<TwoPhaseFrontend> hector = std::make_unique<HectorFrontend>(c);
    if (c.matcher.sparse_widen_evidence_ratio > 0.0)
      hector = std::make_unique<SparseWiden>(std::move(hector), c.matcher);
    if (c.matcher.sparse_lag) return std::make_unique<SparseLag>(std::move(hector), c.matcher);
    return std::make_unique<MeasureAndIntegrate>(std::move(hector));
  };
  const Pose2 T_map_base_initial = config.initial_pose.pose();
  const int members = config.matcher.sparse_ensemble_members;
  if (members <= 1) return make_member(T_map_base_initial);
  // The members' grids are offset by fractions of a cell of the wide search's level.
  const double cell_m = config.map.resolution_m * std::pow(2.0, std::min(1, config.map.levels - 1));
  return std::make_unique<SparseEnsemble>(make_member, T_map_base_initial, members, cell_m);
}

}  // namespace

std::unique_ptr<Frontend> make_frontend(const FrontendConfig& config) {
  if (config.kind == "icp") return std::make_unique<IcpFrontend>(config);
  auto frontend = make_hector(config);
  if (!config.calibration.extrinsic_yaw) return frontend;
  return std::make_unique<CalibratedFrontend>(std::move(frontend), config);
}

}  // namespace traverse::frontend
