#include "scene.hpp"

#include <algorithm>
#include <cmath>

namespace traverse::viewer {

Scene::Scene(const SceneConfig& config) : config_(config) {}

void Scene::add_profile(int64_t utime, std::vector<std::array<int16_t, 3>> p_base_mm) {
  if (p_base_mm.empty()) {
    ++counters_.profiles_rejected;
    return;
  }
  // A copy of points held (a late viewer's answer overlapping what came live, or answered twice):
  // a profile's preview points lie in distinct cells, so a part whose first point is held is one.
  if (auto held = by_utime_.find(utime); held != by_utime_.end()) {
    const auto& pts = profiles_[held->second].p_base_mm;
    if (std::find(pts.begin(), pts.end(), p_base_mm.front()) != pts.end()) {
      ++counters_.profiles_repeated;
      return;
    }
  }
  const int64_t room = config_.max_points - points_;
  if (room <= 0) {
    ++counters_.profiles_rejected;
    counters_.points_dropped += static_cast<int64_t>(p_base_mm.size());
    return;
  }
  if (static_cast<int64_t>(p_base_mm.size()) > room) {
    counters_.points_dropped += static_cast<int64_t>(p_base_mm.size()) - room;
    p_base_mm.resize(static_cast<std::size_t>(room));
  }
  points_ += static_cast<int64_t>(p_base_mm.size());
  auto [it, fresh] = by_utime_.try_emplace(utime, static_cast<uint32_t>(profiles_.size()));
  if (fresh) {
    profiles_.push_back({utime, std::move(p_base_mm), Pose2(), false});
  } else {
    // The rest of a profile split across messages: its points are sent again whole.
    Profile& p = profiles_[it->second];
    p.p_base_mm.insert(p.p_base_mm.end(), p_base_mm.begin(), p_base_mm.end());
    if (p.placed) moved_.insert(it->second);
  }
  place(it->second);
}

void Scene::place(uint32_t index) {
  Profile& p = profiles_[index];
  const std::optional<Pose2> T = trajectory_.pose_at(p.utime);
  if (!T) return;
  if (!p.placed) {
    p.placed = true;
    p.T_map_base = *T;
    new_.insert(index);
    moved_.erase(index);
  } else if (T->vector() != p.T_map_base.vector()) {
    p.T_map_base = *T;
    if (!new_.count(index)) moved_.insert(index);
  }
}

void Scene::set_segment(const mapper::TrajectorySegment& segment, int32_t revision) {
  if (!mapper::TrajectoryStore::valid(segment)) {
    ++counters_.segments_rejected;
    return;
  }
  auto known = revisions_.find(segment.key_id_first);
  if (known != revisions_.end() && revision <= known->second) {
    ++counters_.segments_stale;
    return;
  }
  revisions_[segment.key_id_first] = revision;
  trajectory_.set(segment);
  // The profiles it covers (placed now, or moved).
  for (auto it = by_utime_.lower_bound(segment.utime_first());
       it != by_utime_.end() && it->first <= segment.utime_last(); ++it) {
    place(it->second);
  }
  // Drawn: poses at least trajectory_step_m apart, and the last one.
  Polyline line{segment.key_id_first, revision, {}};
  for (std::size_t i = 0; i < segment.utimes.size(); ++i) {
    const Pose2& T = segment.T_world_base[i];
    const bool last = i + 1 == segment.utimes.size();
    if (!line.xy.empty() && !last) {
      const auto& b = line.xy.back();
      if (std::hypot(T.x() - b[0], T.y() - b[1]) < config_.trajectory_step_m) continue;
    }
    line.xy.push_back({static_cast<float>(T.x()), static_cast<float>(T.y())});
  }
  polylines_[segment.key_id_first] = std::move(line);
  changed_segments_.insert(segment.key_id_first);
  if (!trajectory_end_ || segment.utime_last() >= trajectory_end_->utime) {
    trajectory_end_ = StampedPose{segment.utime_last(), segment.T_world_base.back()};
    pose_changed_ = true;
  }
}

void Scene::set_annotations(const Legend& legend, const std::vector<KeyAnnotation>& keys) {
  if (legend.levels.empty()) {
    counters_.annotations_rejected += static_cast<int64_t>(keys.size());
    return;
  }
  if (!legend_ || !(*legend_ == legend)) {
    legend_ = legend;
    legend_changed_ = true;
  }
  const int n = static_cast<int>(legend.levels.size());
  for (const KeyAnnotation& k : keys) {
    if (k.level < 0 || k.level >= n || !std::isfinite(k.x) || !std::isfinite(k.y)) {
      ++counters_.annotations_rejected;
      continue;
    }
    annotations_[k.id] = k;
    changed_annotations_.insert(k.id);
  }
}

void Scene::set_frontend_pose(int64_t utime, const Pose2& T_map_base) {
  if (!frontend_.empty() && utime <= frontend_.back().utime) return;
  frontend_.push_back({utime, T_map_base});
  const int64_t keep_us = static_cast<int64_t>(config_.pose_history_s * 1e6);
  while (frontend_.size() > 2 && frontend_.front().utime < utime - keep_us) frontend_.pop_front();
  pose_changed_ = true;
}

std::optional<Pose2> Scene::frontend_at(int64_t utime) const {
  auto hi = std::lower_bound(frontend_.begin(), frontend_.end(), utime,
                             [](const StampedPose& p, int64_t t) { return p.utime < t; });
  if (hi == frontend_.end()) return std::nullopt;
  if (hi == frontend_.begin())
    return hi->utime == utime ? std::optional(hi->T_map_base) : std::nullopt;
  const auto lo = std::prev(hi);
  return mapper::interpolate_linear(lo->utime, lo->T_map_base, hi->utime, hi->T_map_base, utime);
}

std::optional<StampedPose> Scene::current_pose() const {
  if (frontend_.empty()) return trajectory_end_;
  const StampedPose& newest = frontend_.back();
  if (!trajectory_end_) return newest;
  if (trajectory_end_->utime >= newest.utime) return trajectory_end_;
  // T_map_base(now) = T_corrected(end) * T_frontend(end)^-1 * T_frontend(now).
  const std::optional<Pose2> fe_end = frontend_at(trajectory_end_->utime);
  if (!fe_end) return trajectory_end_;
  return StampedPose{newest.utime,
                     trajectory_end_->T_map_base * fe_end->inverse() * newest.T_map_base};
}

Changes Scene::take_changes() {
  Changes c;
  c.new_profiles.assign(new_.begin(), new_.end());
  c.moved_profiles.assign(moved_.begin(), moved_.end());
  c.segments.assign(changed_segments_.begin(), changed_segments_.end());
  c.annotations.assign(changed_annotations_.begin(), changed_annotations_.end());
  c.legend = legend_changed_;
  c.pose = pose_changed_;
  new_.clear();
  moved_.clear();
  changed_segments_.clear();
  changed_annotations_.clear();
  legend_changed_ = pose_changed_ = false;
  return c;
}

}  // namespace traverse::viewer
