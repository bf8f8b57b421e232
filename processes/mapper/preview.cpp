#include "preview.hpp"

#include <algorithm>
#include <cmath>

#include "config.hpp"

namespace traverse::mapper {

std::optional<std::string> validate(const PreviewConfig& c) {
  ConfigCheck check;
  // 21 bits per axis: 2^20 cells either side of the origin.
  check.in_range("cell_m", c.cell_m, 0.001, 100.0);
  check.in_range("max_points_per_message", c.max_points_per_message, 1, 10000);
  check.in_range("resend_max_bytes", c.resend_max_bytes, int64_t{1} << 10, int64_t{1} << 34);
  return check.problem();
}

std::optional<uint64_t> preview_cell(double x, double y, double z, double cell_m) {
  constexpr double kHalf = 1 << 20;  // cell index offset: 21 bits per axis
  const double ix = std::floor(x / cell_m) + kHalf;
  const double iy = std::floor(y / cell_m) + kHalf;
  const double iz = std::floor(z / cell_m) + kHalf;
  if (!(ix >= 0 && ix < 2 * kHalf && iy >= 0 && iy < 2 * kHalf && iz >= 0 && iz < 2 * kHalf)) {
    return std::nullopt;
  }
  return static_cast<uint64_t>(ix) | static_cast<uint64_t>(iy) << 21 |
         static_cast<uint64_t>(iz) << 42;
}

uint64_t preview_cell_doubled(uint64_t cell) {
  // i = floor(x / c) + 2^20, and floor(x / 2c) = floor(floor(x / c) / 2) (halving is exact in
  // floating point too): i' = floor((i - 2^20) / 2) + 2^20 = (i >> 1) + 2^19.
  constexpr uint64_t kAxis = (uint64_t{1} << 21) - 1;
  uint64_t out = 0;
  for (int shift = 0; shift < 63; shift += 21) {
    out |= (((cell >> shift & kAxis) >> 1) + (uint64_t{1} << 19)) << shift;
  }
  return out;
}

CloudPreview::CloudPreview(const PreviewConfig& config) : config_(config) {}

void CloudPreview::add(int64_t utime, const Pose2& T_world_base,
                       const std::vector<Eigen::Vector3f>& p_world) {
  const double c = std::cos(T_world_base.theta()), s = std::sin(T_world_base.theta());
  PreviewProfile out{utime, {}, T_world_base};
  std::lock_guard lock(mutex_);
  // Neighbouring beams are millimetres apart: most fall in the cell the one before fell in, which
  // is then known to be taken without asking the set (a lookup per point cost the mapper 20 %).
  uint64_t previous = ~uint64_t{0};
  for (const Eigen::Vector3f& p : p_world) {
    const std::optional<uint64_t> cell = preview_cell(p.x(), p.y(), p.z(), config_.cell_m);
    if (!cell) continue;
    const uint64_t key = *cell;
    if (key == previous) continue;
    previous = key;
    if (!cells_.insert(key).second) continue;
    // Back into the base frame at utime: R^T (p - t), z unchanged (planar pose).
    const double dx = p.x() - T_world_base.x(), dy = p.y() - T_world_base.y();
    const double bx = c * dx + s * dy, by = -s * dx + c * dy;
    auto mm = [](double v) {
      return static_cast<int16_t>(std::clamp(std::lround(v * 1000.0), -32767L, 32767L));
    };
    out.p_base_mm.push_back({mm(bx), mm(by), mm(p.z())});
  }
  if (out.p_base_mm.empty()) return;
  points_ += static_cast<int64_t>(out.p_base_mm.size());
  pending_.push_back(std::move(out));
}

std::vector<std::vector<PreviewProfile>> CloudPreview::take() {
  std::vector<PreviewProfile> pending;
  {
    std::lock_guard lock(mutex_);
    pending.swap(pending_);
  }
  const std::size_t max = static_cast<std::size_t>(config_.max_points_per_message);
  std::vector<std::vector<PreviewProfile>> groups;
  std::size_t in_group = max;  // points in the last group: start a new one first
  for (PreviewProfile& p : pending) {
    for (std::size_t first = 0; first < p.p_base_mm.size();) {
      if (in_group == max) {
        groups.emplace_back();
        in_group = 0;
      }
      const std::size_t n = std::min(max - in_group, p.p_base_mm.size() - first);
      PreviewProfile part{p.utime, {}, p.T_world_base};
      part.p_base_mm.assign(p.p_base_mm.begin() + static_cast<std::ptrdiff_t>(first),
                            p.p_base_mm.begin() + static_cast<std::ptrdiff_t>(first + n));
      groups.back().push_back(std::move(part));
      in_group += n;
      first += n;
    }
  }
  return groups;
}

int64_t CloudPreview::points() const {
  std::lock_guard lock(mutex_);
  return points_;
}

int64_t CloudPreview::cells() const {
  std::lock_guard lock(mutex_);
  return static_cast<int64_t>(cells_.size());
}

}  // namespace traverse::mapper
