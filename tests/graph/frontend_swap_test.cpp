// The frontend swapped at the midpoint of a simulated route (scripts/frontend-swap.sh): the
// swapped run's position RMSE within 20 % of the better of the two frontends alone, and no step
// around the swap off by more than 5 cm.
#include <gtest/gtest.h>

#include "graph_test_util.hpp"

namespace traverse::graph_test {
namespace {

double number(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\": ");
  EXPECT_NE(at, std::string::npos) << key << " in " << json;
  return at == std::string::npos ? -1.0 : std::stod(json.substr(at + key.size() + 4));
}

// The ICP frontend is the better of the two on this stretch (0.66 against 0.94 mm position
// RMSE): swapped from it to Hector, the swapped run stays within 20 % of it. The other way round
// cannot (Hector's first half alone is further from ICP's than 20 %): docs/frontends.md.
TEST(FrontendSwap, IcpToHectorAtTheMidpointOfASimulatedRoute) {
  const auto r = run("TRAVERSE_BIN_DIR=" + bin_dir() +
                         " scripts/frontend-swap.sh office-s2 --profile ideal --seed 1 "
                         "--duration 40 --from icp --to hector",
                     600);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string json = r.output.substr(r.output.rfind("{\"route\""));
  const double hector = number(json, "hector_alone_rmse_m"), icp = number(json, "icp_alone_rmse_m");
  const double swapped = number(json, "swapped_rmse_m");
  std::printf("swap: hector %.5f m, icp %.5f m, swapped %.5f m\n", hector, icp, swapped);
  EXPECT_LE(swapped, 1.2 * std::min(hector, icp)) << json;
  EXPECT_LT(number(json, "swap_step_error_max_m"), 0.05) << json;
}

}  // namespace
}  // namespace traverse::graph_test
