#include "preview_resend.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <unordered_set>

namespace traverse::mapper {

PreviewResend::PreviewResend(double cell_m, int64_t max_bytes)
    : cell_m_(cell_m), max_bytes_(max_bytes) {}

int64_t PreviewResend::bytes() const {
  return points_ * static_cast<int64_t>(sizeof(std::array<int16_t, 3>)) +
         static_cast<int64_t>(kept_.size()) * kProfileBytes;
}

void PreviewResend::add(const PreviewProfile& profile) {
  if (profile.p_base_mm.empty()) return;
  auto [it, fresh] = kept_.try_emplace(profile.utime);
  Kept& k = it->second;
  if (fresh) {
    k.x = static_cast<float>(profile.T_world_base.x());
    k.y = static_cast<float>(profile.T_world_base.y());
    k.theta = static_cast<float>(profile.T_world_base.theta());
  }
  k.p_base_mm.reserve(k.p_base_mm.size() + profile.p_base_mm.size());
  k.p_base_mm.insert(k.p_base_mm.end(), profile.p_base_mm.begin(), profile.p_base_mm.end());
  points_ += static_cast<int64_t>(profile.p_base_mm.size());
  if (bytes() > max_bytes_) compact();
}

void PreviewResend::restart() {
  resending_ = !kept_.empty();
  next_utime_ = kept_.empty() ? 0 : kept_.begin()->first;
  next_point_ = 0;
}

std::vector<PreviewProfile> PreviewResend::next(std::size_t max_points) {
  std::vector<PreviewProfile> out;
  if (!resending_) return out;
  std::size_t n = 0;
  auto it = kept_.lower_bound(next_utime_);
  while (it != kept_.end() && n < max_points) {
    const Kept& k = it->second;
    const std::size_t take = std::min(max_points - n, k.p_base_mm.size() - next_point_);
    const auto first = k.p_base_mm.begin() + static_cast<std::ptrdiff_t>(next_point_);
    out.push_back(
        {it->first, {first, first + static_cast<std::ptrdiff_t>(take)}, Pose2(k.x, k.y, k.theta)});
    n += take;
    next_point_ += take;
    if (next_point_ == k.p_base_mm.size()) {
      ++it;
      next_point_ = 0;
    }
  }
  resending_ = it != kept_.end();
  if (resending_) next_utime_ = it->first;
  return out;
}

void PreviewResend::compact() {
  const auto t0 = std::chrono::steady_clock::now();
  const int64_t before_points = points_;
  const std::size_t before_profiles = kept_.size();
  thin();
  while (bytes() > max_bytes_ / 2 && cell_m_ < 1e3) {
    cell_m_ *= 2.0;
    thin();
  }
  // An answer under way that was inside a profile goes on with the next one: the thinned
  // profile's points are no longer where they were.
  if (resending_ && next_point_ > 0) {
    const auto it = kept_.upper_bound(next_utime_);
    next_point_ = 0;
    resending_ = it != kept_.end();
    if (resending_) next_utime_ = it->first;
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++counters_.compactions;
  counters_.points_compacted += before_points - points_;
  counters_.profiles_compacted += static_cast<int64_t>(before_profiles - kept_.size());
  counters_.compact_total_s += s;
  counters_.compact_max_s = std::max(counters_.compact_max_s, s);
}

void PreviewResend::thin() {
  std::unordered_set<uint64_t> taken;
  taken.reserve(static_cast<std::size_t>(points_));
  points_ = 0;
  for (auto it = kept_.begin(); it != kept_.end();) {
    Kept& k = it->second;
    const double c = std::cos(k.theta), s = std::sin(k.theta);
    std::erase_if(k.p_base_mm, [&](const std::array<int16_t, 3>& q) {
      const double bx = q[0] * 1e-3, by = q[1] * 1e-3;
      const std::optional<uint64_t> cell =
          preview_cell(k.x + c * bx - s * by, k.y + s * bx + c * by, q[2] * 1e-3, cell_m_);
      return !cell || !taken.insert(*cell).second;
    });
    if (k.p_base_mm.empty()) {
      it = kept_.erase(it);
      continue;
    }
    k.p_base_mm.shrink_to_fit();
    points_ += static_cast<int64_t>(k.p_base_mm.size());
    ++it;
  }
}

}  // namespace traverse::mapper
