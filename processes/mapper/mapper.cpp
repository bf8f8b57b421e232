#include "mapper.hpp"

#include <algorithm>
#include <cmath>

namespace traverse::mapper {

namespace {

bool in_footprint(const Footprint& f, const Eigen::Vector3d& p) {
  return p.x() >= f.x_min && p.x() <= f.x_max && p.y() >= f.y_min && p.y() <= f.y_max &&
         p.z() >= f.z_min && p.z() <= f.z_max;
}

}  // namespace

Mapper::Mapper(const MapperConfig& config, const Eigen::Isometry3d& T_base_laser)
    : config_(config),
      T_base_laser_(T_base_laser),
      range_quantum_m_(config.range_max_m / 65535.0),
      tree_(std::make_unique<octomap::OcTree>(config.resolution_m)) {}

Mapper::Stored Mapper::compress(const Profile& p) {
  Stored s;
  s.utime_first = p.utime_first;
  s.utime_last = p.utime_last;
  s.angle_first = p.angle_first;
  s.angle_step = p.angle_step;
  s.range_q.assign(p.ranges.size(), 0);
  s.intensity = p.intensities.empty() ? std::vector<uint8_t>(p.ranges.size(), 0) : p.intensities;
  for (std::size_t i = 0; i < p.ranges.size(); ++i) {
    const double r = p.ranges[i];
    if (!std::isfinite(r) || r < config_.range_min_m || r > config_.range_max_m || r <= 0) continue;
    const double a = p.angle_first + static_cast<double>(i) * p.angle_step;
    const Eigen::Vector3d p_base =
        T_base_laser_ * Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0);
    if (in_footprint(config_.footprint, p_base)) {
      ++points_filtered_;
      continue;
    }
    s.range_q[i] = static_cast<uint16_t>(std::clamp(std::lround(r / range_quantum_m_), 1L, 65535L));
    ++s.n_points;
  }
  return s;
}

bool Mapper::add_profile(const Profile& p) {
  if (p.ranges.size() < 2 || p.utime_last < p.utime_first ||
      (!p.intensities.empty() && p.intensities.size() != p.ranges.size())) {
    return false;
  }
  pending_.push_back(compress(p));
  try_pending();
  return true;
}

bool Mapper::place(const Stored& s, std::vector<Eigen::Vector3f>& pts,
                   std::vector<int>& beams) const {
  pts.clear();
  beams.clear();
  if (!trajectory_.covers(s.utime_first, s.utime_last)) return false;
  const int n = static_cast<int>(s.range_q.size());
  const double dt = static_cast<double>(s.utime_last - s.utime_first) / (n - 1);
  const Eigen::Matrix3d R_bl = T_base_laser_.linear();
  const Eigen::Vector3d t_bl = T_base_laser_.translation();
  const TrajectorySegment* seg = nullptr;
  std::size_t j = 1;
  for (int i = 0; i < n; ++i) {
    if (s.range_q[i] == 0) continue;
    const int64_t t = s.utime_first + std::llround(i * dt);
    // Walk the trajectory forward with the beams (they are in time order).
    if (!seg || t > seg->utime_last()) {
      seg = trajectory_.segment_at(t);
      j = 1;
    }
    while (j + 1 < seg->utimes.size() && seg->utimes[j] < t) ++j;
    const Pose2 T = interpolate_linear(seg->utimes[j - 1], seg->T_world_base[j - 1], seg->utimes[j],
                                       seg->T_world_base[j], t);
    const double r = s.range_q[i] * range_quantum_m_;
    const double a = s.angle_first + static_cast<double>(i) * s.angle_step;
    const Eigen::Vector3d p_base =
        R_bl * Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0) + t_bl;
    const double c = std::cos(T.theta()), sn = std::sin(T.theta());
    pts.emplace_back(static_cast<float>(T.x() + c * p_base.x() - sn * p_base.y()),
                     static_cast<float>(T.y() + sn * p_base.x() + c * p_base.y()),
                     static_cast<float>(p_base.z()));
    beams.push_back(i);
  }
  return true;
}

octomap::KeySet Mapper::voxel_keys(const Stored& s) const {
  std::vector<Eigen::Vector3f> pts;
  std::vector<int> beams;
  octomap::KeySet keys;
  if (!place(s, pts, beams)) return keys;
  // One hit per voxel per profile, so the counts do not depend on how often a voxel is sampled.
  for (const auto& p : pts) {
    octomap::OcTreeKey k;
    if (tree_->coordToKeyChecked(p.x(), p.y(), p.z(), k)) keys.insert(k);
  }
  return keys;
}

void Mapper::set_voxel(const octomap::OcTreeKey& key, uint32_t hits) {
  if (hits == 0) {
    tree_->setNodeValue(key, tree_->getClampingThresMinLog(), true);
    return;
  }
  // The same float steps as `hits` calls of updateNode(key, true), clamped the same way.
  const float hit = tree_->getProbHitLog(), max = tree_->getClampingThresMaxLog();
  float v = 0.0f;
  for (uint32_t i = 0; i < hits && v < max; ++i) v = std::min(v + hit, max);
  tree_->setNodeValue(key, v, true);
}

void Mapper::try_pending() {
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (!trajectory_.covers(it->utime_first, it->utime_last)) {
      ++it;
      continue;
    }
    Stored s = std::move(*it);
    it = pending_.erase(it);
    s.key_id = trajectory_.segment_at(s.utime_first)->key_id_first;
    for (const auto& k : voxel_keys(s)) {
      ++hits_[k];
      tree_->updateNode(k, true, true);
    }
    points_ += s.n_points;
    auto pos = std::upper_bound(stored_.begin(), stored_.end(), s.utime_first,
                                [](int64_t t, const Stored& x) { return t < x.utime_first; });
    stored_.insert(pos, std::move(s));
  }
}

bool Mapper::set_segment(const TrajectorySegment& segment) {
  if (segment.utimes.empty()) return false;
  // Profiles placed with the poses this segment replaces lose their hits now (old poses).
  const int64_t t0 = segment.utimes.front(), t1 = segment.utimes.back();
  const TrajectorySegment* old = trajectory_.segment_at(t0);
  if (old && old->utime_first() == t0 && old->utimes == segment.utimes &&
      old->T_world_base.size() == segment.T_world_base.size()) {
    bool same = true;
    for (std::size_t i = 0; same && i < segment.T_world_base.size(); ++i) {
      same = old->T_world_base[i].vector() == segment.T_world_base[i].vector();
    }
    if (same) return true;  // sent again unchanged: nothing moves
  }
  if (old && old->utime_first() == t0) {
    for (Stored& s : stored_) {
      if (s.dirty || s.utime_last < t0 || s.utime_first > std::max(t1, old->utime_last())) continue;
      for (const auto& k : voxel_keys(s)) {
        if (--hits_[k] == 0) hits_.erase(k);
        touched_.insert(k);
      }
      s.dirty = true;
    }
  }
  if (!trajectory_.set(segment)) return false;
  try_pending();
  return true;
}

std::size_t Mapper::apply_moves() {
  std::size_t moved = 0;
  for (Stored& s : stored_) {
    if (!s.dirty) continue;
    s.dirty = false;
    ++moved;
    s.key_id = trajectory_.segment_at(s.utime_first)->key_id_first;
    for (const auto& k : voxel_keys(s)) {
      ++hits_[k];
      touched_.insert(k);
    }
  }
  for (const auto& k : touched_) {
    auto it = hits_.find(k);
    set_voxel(k, it == hits_.end() ? 0 : it->second);
  }
  touched_.clear();
  profiles_replaced_ += static_cast<int64_t>(moved);
  return moved;
}

std::size_t Mapper::drop_stale(int64_t now_utime) {
  const int64_t limit = now_utime - static_cast<int64_t>(config_.max_pending_s * 1e6);
  const std::size_t before = pending_.size();
  std::erase_if(pending_, [limit](const Stored& s) { return s.utime_last < limit; });
  return before - pending_.size();
}

void Mapper::for_each_point(const std::function<void(const CloudPoint&)>& f) const {
  std::vector<Eigen::Vector3f> pts;
  std::vector<int> beams;
  for (const Stored& s : stored_) {
    if (!place(s, pts, beams)) continue;
    const double dt = static_cast<double>(s.utime_last - s.utime_first) / (s.range_q.size() - 1);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      f({pts[i], s.intensity[beams[i]], s.utime_first + std::llround(beams[i] * dt), s.key_id});
    }
  }
}

int64_t Mapper::placed_points() const {
  int64_t n = 0;
  for (const Stored& s : stored_) {
    if (trajectory_.covers(s.utime_first, s.utime_last)) n += s.n_points;
  }
  return n;
}

void Mapper::finish_octree_for_export() { tree_->updateInnerOccupancy(); }

std::size_t Mapper::profile_bytes() const {
  std::size_t b = 0;
  for (const Stored& s : stored_) {
    b += sizeof(Stored) + s.range_q.capacity() * sizeof(uint16_t) + s.intensity.capacity();
  }
  return b;
}

}  // namespace traverse::mapper
