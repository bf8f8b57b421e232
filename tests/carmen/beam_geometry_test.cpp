// Which FLASER beam geometry is right is decided by the data: scans placed at the reference poses
// make the sharpest map when their beam angles are right. Sharpness = entropy of the hit
// distribution over a 5 cm grid (lower = points concentrated on fewer cells = crisper walls).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <unordered_map>

#include "log_reader.hpp"

namespace traverse::carmen {
namespace {

struct MapStats {
  double entropy_nats = 0.0;
  int64_t cells = 0;
  int64_t points = 0;
};

MapStats accumulate(const std::string& path, FlaserGeometry geometry) {
  constexpr double kCellM = 0.05, kMaxRangeM = 20.0;
  std::unordered_map<int64_t, int64_t> hits;
  MapStats s;
  Reader reader(path, geometry);
  while (auto scan = reader.next()) {
    const double c = std::cos(scan->theta_rad), sn = std::sin(scan->theta_rad);
    for (std::size_t i = 0; i < scan->ranges.size(); ++i) {
      const double r = scan->ranges[i];
      if (r <= 0.05 || r > kMaxRangeM) continue;
      const double a = scan->beams.angle_first + static_cast<double>(i) * scan->beams.angle_step;
      const double px = r * std::cos(a), py = r * std::sin(a);
      const double wx = scan->x_m + c * px - sn * py, wy = scan->y_m + sn * px + c * py;
      const int64_t ix = std::llround(wx / kCellM), iy = std::llround(wy / kCellM);
      ++hits[(ix << 32) ^ (iy & 0xffffffff)];
      ++s.points;
    }
  }
  for (const auto& [cell, n] : hits) {
    const double p = static_cast<double>(n) / static_cast<double>(s.points);
    s.entropy_nats -= p * std::log(p);
  }
  s.cells = static_cast<int64_t>(hits.size());
  return s;
}

int beams_in_first_scan(const std::string& path) {
  Reader reader(path);
  const auto scan = reader.next();
  return scan ? static_cast<int>(scan->ranges.size()) : 0;
}

class BeamGeometry : public ::testing::TestWithParam<std::string> {};

TEST_P(BeamGeometry, StandardReadingGivesTheSharpestMap) {
  const std::string path = "../shared/data/carmen/" + GetParam() + "-corrected.log.gz";
  const int n = beams_in_first_scan(path);
  ASSERT_GT(n, 0);
  const MapStats chosen = accumulate(path, FlaserGeometry::kStandard);
  ASSERT_GT(chosen.points, 10000);
  const BeamAngles standard = flaser_beam_angles(n, FlaserGeometry::kStandard);
  int compared = 0;
  for (const char* name : {"half_open", "closed", "centered", "reversed"}) {
    const FlaserGeometry g = *parse_flaser_geometry(name);
    const BeamAngles a = flaser_beam_angles(n, g);
    if (a.angle_first == standard.angle_first && a.angle_step == standard.angle_step) continue;
    const MapStats other = accumulate(path, g);
    std::printf("%s (%d beams): %s: %.4f nats, %lld cells; standard: %.4f nats, %lld cells\n",
                GetParam().c_str(), n, name, other.entropy_nats,
                static_cast<long long>(other.cells), chosen.entropy_nats,
                static_cast<long long>(chosen.cells));
    EXPECT_LT(chosen.entropy_nats, other.entropy_nats) << name;
    ++compared;
  }
  EXPECT_EQ(compared, 3);  // the standard reading is exactly one of the four others
}

INSTANTIATE_TEST_SUITE_P(RadishLogs, BeamGeometry,
                         ::testing::Values("intel", "aces", "csail", "freiburg-079"));

}  // namespace
}  // namespace traverse::carmen
