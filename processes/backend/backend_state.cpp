#include "backend_state.hpp"

#include <chrono>
#include <filesystem>
#include <stdexcept>

namespace traverse::backend {
namespace {

const std::string kMagic = "TRVBKG03";  // graph.state, version 3 (calibrated marginals)
// Bounds on what a snapshot may claim, so a damaged count cannot allocate without end.
constexpr uint64_t kMaxItems = 50'000'000;

void put(StateWriter& w, const Eigen::Matrix3d& m) {
  for (int i = 0; i < 9; ++i) w.put(m(i / 3, i % 3));
}
bool get(StateReader& r, Eigen::Matrix3d& m) {
  for (int i = 0; i < 9; ++i) {
    if (!r.get(m(i / 3, i % 3))) return false;
  }
  return true;
}

void put(StateWriter& w, const PreparedPose& p) {
  w.put(p.utime);
  w.put(p.T_world_base);
  w.put(p.frontend.utime);
  w.put(p.frontend.T_map_base);
  put(w, p.frontend.covariance);
  w.put(p.travel_m);
  w.put<uint8_t>(p.sparse ? 1 : 0);
}
bool get(StateReader& r, PreparedPose& p) {
  uint8_t sparse = 0;
  const bool ok = r.get(p.utime) && r.get(p.T_world_base) && r.get(p.frontend.utime) &&
                  r.get(p.frontend.T_map_base) && get(r, p.frontend.covariance) &&
                  r.get(p.travel_m) && r.get(sparse);
  p.sparse = sparse != 0;
  return ok;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

BackendStateStore::BackendStateStore(std::string dir, int64_t period_us, bool durable)
    : dir_(std::move(dir)), period_us_(period_us), durable_(durable) {
  std::filesystem::create_directories(dir_);
}

std::string BackendStateStore::snapshot(const Backend& b) const {
  StateWriter w;
  w.put(b.counters_);
  w.put<int32_t>(b.optimisations_);
  w.put<int32_t>(b.first_unreported_key_);
  w.put<uint64_t>(b.first_unreported_closure_);
  w.put<uint64_t>(b.key_poses_.size());
  for (const KeyPose& k : b.key_poses_) {
    w.put(k.utime);
    w.put(k.T_world_base);
    w.put(k.travel_m);
    put(w, k.covariance);
    put(w, k.calibrated_covariance);
  }
  const PoseGraph& g = b.graph_;
  w.put<uint64_t>(g.poses.size());
  for (std::size_t i = 0; i < g.poses.size(); ++i) {
    w.put(g.poses[i]);
    w.put(g.ids[i]);
    w.put<uint8_t>(g.fixed[i] ? 1 : 0);
  }
  w.put<uint64_t>(g.edges.size());
  for (const Edge& e : g.edges) {
    w.put<int32_t>(e.from);
    w.put<int32_t>(e.to);
    w.put(e.T_from_to);
    put(w, e.information);
  }
  w.put_vector(b.edge_kinds_);
  w.put<uint64_t>(b.closures_.size());
  for (const LoopClosure& c : b.closures_) {
    w.put<int32_t>(c.from);
    w.put<int32_t>(c.to);
    w.put(c.T_from_to);
    put(w, c.covariance);
    w.put(c.response);
    w.put<int32_t>(c.candidates_tried);
    w.put(c.chi2_increase);
  }
  put(w, b.last_key_);
  w.put<int32_t>(b.scans_.size());
  return w.bytes();
}

std::optional<ResumedState> BackendStateStore::resume(Backend& b) {
  const std::string graph_path = dir_ + "/graph.state", scans_path = dir_ + "/key_scans.rec";
  std::string error;
  const std::optional<std::string> payload = read_snapshot(graph_path, kMagic, &error);
  if (!payload) {
    if (!error.empty()) throw std::runtime_error(error);
    // No snapshot yet: key scans appended before the first one belong to no state.
    if (!scans_.open(scans_path, 0, &error)) throw std::runtime_error(error);
    return std::nullopt;
  }
  const auto damaged = [&] { return std::runtime_error(graph_path + " is inconsistent"); };
  StateReader r(*payload);
  uint64_t n = 0;
  int32_t optimisations = 0, first_unreported_key = 0, i0 = 0, i1 = 0, scans = 0;
  uint64_t first_unreported_closure = 0;
  if (!r.get(b.counters_) || !r.get(optimisations) || !r.get(first_unreported_key) ||
      !r.get(first_unreported_closure) || !r.get(n) || n > kMaxItems)
    throw damaged();
  b.key_poses_.resize(n);
  for (KeyPose& k : b.key_poses_) {
    if (!r.get(k.utime) || !r.get(k.T_world_base) || !r.get(k.travel_m) || !get(r, k.covariance) ||
        !get(r, k.calibrated_covariance))
      throw damaged();
  }
  PoseGraph& g = b.graph_;
  if (!r.get(n) || n > kMaxItems) throw damaged();
  for (uint64_t i = 0; i < n; ++i) {
    Pose2 T;
    int64_t id = 0;
    uint8_t fixed = 0;
    if (!r.get(T) || !r.get(id) || !r.get(fixed)) throw damaged();
    g.add_vertex(id, T, fixed != 0);
  }
  if (!r.get(n) || n > kMaxItems) throw damaged();
  g.edges.resize(n);
  for (Edge& e : g.edges) {
    if (!r.get(i0) || !r.get(i1) || !r.get(e.T_from_to) || !get(r, e.information)) throw damaged();
    e.from = i0;
    e.to = i1;
  }
  if (!r.get_vector(b.edge_kinds_, kMaxItems) || !r.get(n) || n > kMaxItems) throw damaged();
  b.closures_.resize(n);
  for (LoopClosure& c : b.closures_) {
    if (!r.get(i0) || !r.get(i1) || !r.get(c.T_from_to) || !get(r, c.covariance) ||
        !r.get(c.response) || !r.get(c.candidates_tried) || !r.get(c.chi2_increase))
      throw damaged();
    c.from = i0;
    c.to = i1;
  }
  if (!get(r, b.last_key_) || !r.get(scans) || !r.at_end()) throw damaged();
  if (scans != static_cast<int32_t>(b.key_poses_.size()) ||
      b.edge_kinds_.size() != g.edges.size()) {
    throw damaged();
  }
  // The key scans the snapshot covers; those appended after it are cut off.
  for (const std::string& record : RecordLog::read(scans_path, static_cast<std::size_t>(scans))) {
    StateReader s(record);
    std::vector<float> xy;
    if (!s.get_vector(xy, kMaxItems) || xy.size() % 2 != 0) {
      throw std::runtime_error(scans_path + " is damaged");
    }
    std::vector<Eigen::Vector2f> points(xy.size() / 2);
    for (std::size_t i = 0; i < points.size(); ++i) points[i] = {xy[2 * i], xy[2 * i + 1]};
    b.scans_.add(std::move(points));
  }
  if (!scans_.open(scans_path, static_cast<std::size_t>(scans), &error)) {
    throw std::runtime_error(error);
  }
  scans_stored_ = scans;
  b.optimisations_ = optimisations;
  b.first_unreported_key_ = first_unreported_key;
  b.first_unreported_closure_ = first_unreported_closure;
  b.since_key_.assign(1, b.last_key_);
  b.prep_.resume(b.last_key_, b.counters_.prep);
  last_snapshot_utime_ = b.last_key_.utime;
  return ResumedState{static_cast<int>(b.key_poses_.size()), static_cast<int>(b.closures_.size()),
                      b.last_key_.utime};
}

void BackendStateStore::persist(const Backend& b, bool now) {
  if (!scans_.is_open()) {  // resume() was not called: a new state
    std::string error;
    if (!scans_.open(dir_ + "/key_scans.rec", 0, &error)) {
      ++counters_.snapshot_failures;
      return;
    }
  }
  for (; scans_stored_ < b.scans_.size(); ++scans_stored_) {
    std::vector<float> xy;
    for (const Eigen::Vector2f& p : b.scans_.points(scans_stored_)) {
      xy.push_back(p.x());
      xy.push_back(p.y());
    }
    StateWriter w;
    w.put_vector(xy);
    scans_.append(w.bytes());
    ++counters_.key_scans_appended;
  }
  if (b.key_poses_.empty()) return;
  const int64_t utime = b.key_poses_.back().utime;
  if (!now && last_snapshot_utime_ != INT64_MIN && utime - last_snapshot_utime_ < period_us_) {
    return;
  }
  // The key scans the snapshot counts are written (and, durable, on the disk) before it is.
  const auto t0 = std::chrono::steady_clock::now();
  const std::string payload = snapshot(b);
  if ((durable_ && !scans_.sync()) ||
      !write_snapshot(dir_ + "/graph.state", kMagic, payload, durable_)) {
    ++counters_.snapshot_failures;
    return;
  }
  last_snapshot_utime_ = utime;
  ++counters_.snapshots;
  counters_.last_snapshot_s = seconds_since(t0);
  counters_.total_snapshot_s += counters_.last_snapshot_s;
  counters_.last_snapshot_bytes = static_cast<double>(payload.size());
}

}  // namespace traverse::backend
