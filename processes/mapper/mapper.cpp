#include "mapper.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <thread>

#include "config.hpp"

namespace traverse::mapper {

std::optional<std::string> validate(const Footprint& f) {
  ConfigCheck check;
  check.require(f.x_max >= f.x_min, "x_max", "must be at least x_min");
  check.require(f.y_max >= f.y_min, "y_max", "must be at least y_min");
  check.require(f.z_max >= f.z_min, "z_max", "must be at least z_min");
  return check.problem();
}

std::optional<std::string> validate(const MapperConfig& c) {
  ConfigCheck check;
  check.in_range("resolution_m", c.resolution_m, 0.001, 10.0);
  check.not_negative("range_min_m", c.range_min_m);
  check.require(c.range_max_m > c.range_min_m, "range_max_m", "must exceed range_min_m");
  // OctoMap keys are 16 bits per axis: a point farther than this many leaves from the origin has
  // none.
  check.require(c.range_max_m / c.resolution_m < 30000.0, "range_max_m",
                "must be under 30000 leaves of resolution_m");
  check.nested("footprint", validate(c.footprint));
  check.not_empty("rig_file", c.rig_file);
  check.not_empty("output_dir", c.output_dir);
  check.in_range("poses_per_segment", c.poses_per_segment, 1, 1'000'000);
  check.positive("max_pending_s", c.max_pending_s);
  check.in_range("move_threads", c.move_threads, 1, 64);
  check.nested("preview", validate(c.preview));
  check.nested("resend", validate(c.resend));
  return check.problem();
}

namespace {

bool in_footprint(const Footprint& f, const Eigen::Vector3d& p) {
  return p.x() >= f.x_min && p.x() <= f.x_max && p.y() >= f.y_min && p.y() <= f.y_max &&
         p.z() >= f.z_min && p.z() <= f.z_max;
}

// OctoMap's coordToKeyChecked at the finest level, (int)floor(c / resolution) + 32768 within
// [0, 65536), inlined (the library's is a call per coordinate).
bool to_key(double c, double scale, uint64_t& key) {
  const double k = std::floor(scale * c) + 32768.0;
  if (!(k >= 0.0 && k < 65536.0)) return false;
  key = static_cast<uint64_t>(k);
  return true;
}

octomap::OcTreeKey unpack(uint64_t v) {
  return octomap::OcTreeKey(static_cast<octomap::key_type>(v & 0xffff),
                            static_cast<octomap::key_type>((v >> 16) & 0xffff),
                            static_cast<octomap::key_type>((v >> 32) & 0xffff));
}

}  // namespace

Mapper::Mapper(const MapperConfig& config, const Eigen::Isometry3d& T_base_laser)
    : config_(config),
      T_base_laser_(T_base_laser),
      range_quantum_m_(range_quantum_m(config.range_max_m)),
      tree_(std::make_unique<octomap::OcTree>(config.resolution_m)) {
  key_scale_ = 1.0 / tree_->getResolution();  // as OcTree computes its resolution_factor
}

uint32_t Mapper::beam_table(const Profile& p) {
  for (std::size_t g = 0; g < beam_tables_.size(); ++g) {
    const BeamTable& b = beam_tables_[g];
    if (b.angle_first == p.angle_first && b.angle_step == p.angle_step &&
        b.dir_base.size() == p.ranges.size()) {
      return static_cast<uint32_t>(g);
    }
  }
  BeamTable b{p.angle_first, p.angle_step, {}};
  for (std::size_t i = 0; i < p.ranges.size(); ++i) {
    const double a = p.angle_first + static_cast<double>(i) * p.angle_step;
    b.dir_base.push_back(T_base_laser_.linear() * Eigen::Vector3d(std::cos(a), std::sin(a), 0));
  }
  beam_tables_.push_back(std::move(b));
  return static_cast<uint32_t>(beam_tables_.size() - 1);
}

Mapper::Stored Mapper::compress(const Profile& p) {
  Stored s;
  s.utime_first = p.utime_first;
  s.utime_last = p.utime_last;
  s.geometry = beam_table(p);
  const std::vector<Eigen::Vector3d>& dir = beam_tables_[s.geometry].dir_base;
  s.range_q.assign(p.ranges.size(), 0);
  s.intensity = p.intensities.empty() ? std::vector<uint8_t>(p.ranges.size(), 0) : p.intensities;
  for (std::size_t i = 0; i < p.ranges.size(); ++i) {
    const double r = p.ranges[i];
    if (!std::isfinite(r) || r < config_.range_min_m || r > config_.range_max_m || r <= 0) continue;
    if (in_footprint(config_.footprint, r * dir[i] + T_base_laser_.translation())) {
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

const TrajectorySegment* Mapper::segment_at(int64_t utime, Poses poses) const {
  const TrajectorySegment* current = trajectory_.segment_at(utime);
  if (poses == Poses::kBeforeMoves && current) {
    auto it = before_moves_.find(current->utime_first());
    if (it != before_moves_.end()) return &it->second;  // same times, the poses before the move
  }
  return current;
}

bool Mapper::place(const Stored& s, std::vector<Eigen::Vector3f>& pts, std::vector<int>& beams,
                   Poses poses) const {
  pts.clear();
  beams.clear();
  if (!trajectory_.covers(s.utime_first, s.utime_last)) return false;
  const int n = static_cast<int>(s.range_q.size());
  const double dt = static_cast<double>(s.utime_last - s.utime_first) / (n - 1);
  const std::vector<Eigen::Vector3d>& dir = beam_tables_[s.geometry].dir_base;
  const Eigen::Vector3d t_bl = T_base_laser_.translation();
  const TrajectorySegment* seg = nullptr;
  std::size_t j = 1, interval = 0;  // interval: the j the values below were computed for (0: none)
  int64_t ta = 0, tb = 0;
  double xa = 0, ya = 0, dx = 0, dy = 0, ca = 1, sa = 0, dth = 0;
  for (int i = 0; i < n; ++i) {
    if (s.range_q[i] == 0) continue;
    const int64_t t = s.utime_first + std::llround(i * dt);
    // Walk the trajectory forward with the beams (they are in time order).
    if (!seg || t > seg->utime_last()) {
      seg = segment_at(t, poses);
      j = 1;
      interval = 0;
    }
    while (j + 1 < seg->utimes.size() && seg->utimes[j] < t) ++j;
    if (interval != j) {
      // Pose linear between two trajectory poses: position, and heading the shortest way.
      const Pose2& a = seg->T_world_base[j - 1];
      const Pose2& b = seg->T_world_base[j];
      ta = seg->utimes[j - 1];
      tb = seg->utimes[j];
      xa = a.x();
      ya = a.y();
      dx = b.x() - a.x();
      dy = b.y() - a.y();
      ca = std::cos(a.theta());
      sa = std::sin(a.theta());
      dth = wrap_angle(b.theta() - a.theta());
      interval = j;
    }
    const double u = t <= ta ? 0.0 : (t >= tb ? 1.0 : static_cast<double>(t - ta) / (tb - ta));
    // Rotation by u * dth from heading a; a few mrad between poses 5 ms apart, so a series
    // (error below d^8 / 40320, under 1e-15 for d < 0.05 rad) instead of a sin and a cos per beam.
    const double d = u * dth;
    double cd, sd;
    if (std::abs(d) < 0.05) {
      const double d2 = d * d;
      cd = 1 - d2 / 2 * (1 - d2 / 12 * (1 - d2 / 30));
      sd = d * (1 - d2 / 6 * (1 - d2 / 20 * (1 - d2 / 42)));
    } else {
      cd = std::cos(d);
      sd = std::sin(d);
    }
    const double c = ca * cd - sa * sd, sn = sa * cd + ca * sd;
    const Eigen::Vector3d p_base = (s.range_q[i] * range_quantum_m_) * dir[i] + t_bl;
    pts.emplace_back(static_cast<float>(xa + u * dx + c * p_base.x() - sn * p_base.y()),
                     static_cast<float>(ya + u * dy + sn * p_base.x() + c * p_base.y()),
                     static_cast<float>(p_base.z()));
    beams.push_back(i);
  }
  return true;
}

void Mapper::voxel_keys(const Stored& s, Poses poses, std::vector<uint64_t>& keys) const {
  thread_local std::vector<Eigen::Vector3f> pts;
  thread_local std::vector<int> beams;
  keys.clear();
  if (!place(s, pts, beams, poses)) return;
  // One hit per voxel per profile, so the counts do not depend on how often a voxel is sampled.
  for (const auto& p : pts) {
    uint64_t kx, ky, kz;
    if (!to_key(p.x(), key_scale_, kx) || !to_key(p.y(), key_scale_, ky) ||
        !to_key(p.z(), key_scale_, kz)) {
      continue;
    }
    const uint64_t packed = kx | ky << 16 | kz << 32;
    if (keys.empty() || keys.back() != packed) keys.push_back(packed);  // neighbours often share
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
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

void Mapper::add_hit(uint64_t key) {
  ++hits_[key];
  touched_.push_back(key);
}

void Mapper::remove_hit(uint64_t key) {
  auto it = hits_.find(key);
  if (it != hits_.end() && --it->second == 0) hits_.erase(it);
  touched_.push_back(key);
}

std::pair<std::size_t, std::size_t> Mapper::stored_range(int64_t t0, int64_t t1) const {
  auto by_first = [](const Stored& x, int64_t t) { return x.utime_first < t; };
  const auto a =
      std::lower_bound(stored_.begin(), stored_.end(), t0 - longest_profile_us_, by_first);
  const auto b = std::upper_bound(stored_.begin(), stored_.end(), t1,
                                  [](int64_t t, const Stored& x) { return t < x.utime_first; });
  return {static_cast<std::size_t>(a - stored_.begin()),
          static_cast<std::size_t>(std::max(a, b) - stored_.begin())};
}

void Mapper::try_pending() {
  std::vector<uint64_t> keys;
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (!trajectory_.covers(it->utime_first, it->utime_last)) {
      ++it;
      continue;
    }
    Stored s = std::move(*it);
    it = pending_.erase(it);
    s.key_id = trajectory_.segment_at(s.utime_first)->key_id_first;
    // A profile spanning a segment whose move is not yet applied goes in with the moves, so that
    // every profile in the map was placed with the poses before_moves_ keeps.
    auto moved = before_moves_.upper_bound(s.utime_last);
    if (moved != before_moves_.begin() && std::prev(moved)->second.utime_last() >= s.utime_first) {
      s.dirty = true;
    } else {
      voxel_keys(s, Poses::kCurrent, keys);
      for (uint64_t k : keys) {
        ++hits_[k];
        tree_->updateNode(unpack(k), true, true);
      }
      s.in_map = true;
      first_placed(s);
    }
    points_ += s.n_points;
    longest_profile_us_ = std::max(longest_profile_us_, s.utime_last - s.utime_first);
    auto pos = std::upper_bound(stored_.begin(), stored_.end(), s.utime_first,
                                [](int64_t t, const Stored& x) { return t < x.utime_first; });
    stored_.insert(pos, std::move(s));
  }
}

bool Mapper::set_segment(const TrajectorySegment& segment) {
  if (!TrajectoryStore::valid(segment)) return false;
  const int64_t t0 = segment.utime_first();
  const TrajectorySegment* old = trajectory_.segment_at(t0);
  if (old && old->utime_first() == t0) {
    if (old->utimes == segment.utimes) {
      bool same = true;
      for (std::size_t i = 0; same && i < segment.T_world_base.size(); ++i) {
        same = old->T_world_base[i].vector() == segment.T_world_base[i].vector();
      }
      if (same) return true;  // sent again unchanged: nothing moves
      // Moved: its profiles are placed again at apply_moves(), with these poses and the ones
      // they were placed with (kept from the first move since the last apply_moves()).
      before_moves_.try_emplace(t0, *old);
      const auto [a, b] = stored_range(t0, old->utime_last());
      for (std::size_t i = a; i < b; ++i) {
        if (stored_[i].utime_last >= t0) stored_[i].dirty = true;
      }
    } else {
      // Other times (not sent by the densifier, whose segments run between fixed key poses):
      // the profiles it spans leave the map now, with the poses they were placed with.
      std::vector<uint64_t> keys;
      const auto [a, b] = stored_range(t0, std::max(segment.utime_last(), old->utime_last()));
      for (std::size_t i = a; i < b; ++i) {
        Stored& s = stored_[i];
        if (s.utime_last < t0) continue;
        if (s.in_map) {
          voxel_keys(s, Poses::kBeforeMoves, keys);
          for (uint64_t k : keys) remove_hit(k);
          s.in_map = false;
        }
        s.dirty = true;
      }
      before_moves_.erase(t0);
    }
  }
  trajectory_.set(segment);
  try_pending();
  return true;
}

void Mapper::change(const Stored& s, Change& c) const {
  thread_local std::vector<uint64_t> before, after;
  c.left.clear();
  c.entered.clear();
  voxel_keys(s, Poses::kCurrent, after);
  if (!s.in_map) {
    c.entered = after;
    return;
  }
  voxel_keys(s, Poses::kBeforeMoves, before);
  std::set_difference(before.begin(), before.end(), after.begin(), after.end(),
                      std::back_inserter(c.left));
  std::set_difference(after.begin(), after.end(), before.begin(), before.end(),
                      std::back_inserter(c.entered));
}

std::size_t Mapper::apply_moves() {
  std::vector<std::size_t> dirty;
  for (std::size_t i = 0; i < stored_.size(); ++i) {
    if (stored_[i].dirty) dirty.push_back(i);
  }
  // Blocks of profiles: the changes are found on move_threads threads, then counted in profile
  // order on this one (the same result for any number of threads).
  constexpr std::size_t kBlock = 256;
  std::vector<Change> changes(std::min(kBlock, dirty.size()));
  const std::size_t threads = static_cast<std::size_t>(std::max(1, config_.move_threads));
  std::size_t moved = 0;
  for (std::size_t b0 = 0; b0 < dirty.size(); b0 += kBlock) {
    const std::size_t n = std::min(kBlock, dirty.size() - b0);
    auto work = [&](std::size_t first) {
      for (std::size_t i = first; i < n; i += threads) change(stored_[dirty[b0 + i]], changes[i]);
    };
    std::vector<std::thread> helpers;
    for (std::size_t t = 1; t < threads && t < n; ++t) helpers.emplace_back(work, t);
    work(0);
    for (auto& h : helpers) h.join();
    for (std::size_t i = 0; i < n; ++i) {
      Stored& s = stored_[dirty[b0 + i]];
      const bool first = !s.in_map;
      if (!first) ++moved;
      for (uint64_t k : changes[i].left) remove_hit(k);
      for (uint64_t k : changes[i].entered) add_hit(k);
      s.key_id = trajectory_.segment_at(s.utime_first)->key_id_first;
      s.dirty = false;
      s.in_map = true;
      if (first) first_placed(s);
    }
  }
  before_moves_.clear();
  std::sort(touched_.begin(), touched_.end());
  touched_.erase(std::unique(touched_.begin(), touched_.end()), touched_.end());
  for (uint64_t k : touched_) {
    auto it = hits_.find(k);
    set_voxel(unpack(k), it == hits_.end() ? 0 : it->second);
  }
  touched_.clear();
  profiles_replaced_ += static_cast<int64_t>(moved);
  return moved;
}

void Mapper::first_placed(const Stored& s) const {
  if (!first_placement_) return;
  thread_local std::vector<Eigen::Vector3f> pts;
  thread_local std::vector<int> beams;
  const std::optional<Pose2> T_world_base = trajectory_.pose_at(s.utime_first);
  if (T_world_base && place(s, pts, beams)) first_placement_(s.utime_first, *T_world_base, pts);
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
      f({pts[i], s.intensity[beams[i]], s.utime_first + std::llround(beams[i] * dt), s.key_id, {}});
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
