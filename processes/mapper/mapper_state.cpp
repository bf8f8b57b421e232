#include "mapper_state.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace traverse::mapper {
namespace {

constexpr uint32_t kProfileVersion = 1, kSegmentVersion = 1;
constexpr uint64_t kMaxBeams = 1'000'000, kMaxPoses = 10'000'000;

std::string encode(const Profile& p, double quantum_m) {
  StateWriter w;
  w.put(kProfileVersion);
  w.put(p.utime_first);
  w.put(p.utime_last);
  w.put(p.angle_first);
  w.put(p.angle_step);
  w.put(p.range_min);
  w.put(p.range_max);
  w.put(quantum_m);
  // As Mapper::compress quantises: a range decoded from here is stored by the mapper as the same
  // 16-bit value, so its point lands where the undisturbed mapper put it.
  std::vector<uint16_t> q(p.ranges.size(), 0);
  for (std::size_t i = 0; i < q.size(); ++i) {
    const double r = p.ranges[i];
    const long v = std::isfinite(r) && r > 0 ? std::lround(r / quantum_m) : 0;
    if (v <= 65535) q[i] = static_cast<uint16_t>(v);  // beyond: past range_max_m, no point
  }
  w.put_vector(q);
  w.put_vector(p.intensities);
  return w.bytes();
}

bool decode(const std::string& bytes, Profile& p) {
  StateReader r(bytes);
  uint32_t version = 0;
  double quantum_m = 0;
  std::vector<uint16_t> q;
  if (!r.get(version) || version != kProfileVersion || !r.get(p.utime_first) ||
      !r.get(p.utime_last) || !r.get(p.angle_first) || !r.get(p.angle_step) ||
      !r.get(p.range_min) || !r.get(p.range_max) || !r.get(quantum_m) ||
      !r.get_vector(q, kMaxBeams) || !r.get_vector(p.intensities, kMaxBeams) || !r.at_end()) {
    return false;
  }
  p.ranges.resize(q.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    p.ranges[i] = q[i] == 0 ? NAN : static_cast<float>(q[i] * quantum_m);
  }
  return true;
}

std::string encode(const TrajectorySegment& s, int32_t revision) {
  StateWriter w;
  w.put(kSegmentVersion);
  w.put(s.key_id_first);
  w.put(revision);
  w.put_vector(s.utimes);
  std::vector<double> xyt;
  xyt.reserve(3 * s.T_world_base.size());
  for (const Pose2& T : s.T_world_base) xyt.insert(xyt.end(), {T.x(), T.y(), T.theta()});
  w.put_vector(xyt);
  return w.bytes();
}

bool decode(const std::string& bytes, SavedSegment& s) {
  StateReader r(bytes);
  uint32_t version = 0;
  std::vector<double> xyt;
  if (!r.get(version) || version != kSegmentVersion || !r.get(s.segment.key_id_first) ||
      !r.get(s.revision) || !r.get_vector(s.segment.utimes, kMaxPoses) ||
      !r.get_vector(xyt, 3 * kMaxPoses) || !r.at_end() ||
      xyt.size() != 3 * s.segment.utimes.size()) {
    return false;
  }
  for (std::size_t i = 0; i < xyt.size(); i += 3) {
    s.segment.T_world_base.emplace_back(xyt[i], xyt[i + 1], xyt[i + 2]);
  }
  return true;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

MapperStateStore::MapperStateStore(std::string dir, double range_max_m)
    : dir_(std::move(dir)), range_quantum_m_(Mapper::range_quantum_m(range_max_m)) {
  std::filesystem::create_directories(dir_);
}

std::optional<SavedInputs> MapperStateStore::load() {
  SavedInputs in;
  std::string error;
  std::size_t length = 0;
  const std::string profiles_path = dir_ + "/profiles.rec", segments_path = dir_ + "/segments.rec";
  const std::vector<std::string> profiles = RecordLog::read(profiles_path, SIZE_MAX, &length);
  for (const std::string& bytes : profiles) {
    if (!decode(bytes, in.profiles.emplace_back())) {
      throw std::runtime_error(profiles_path + ": record " + std::to_string(in.profiles.size()) +
                               " is not a profile");
    }
  }
  if (!profiles_.open_at(profiles_path, length, &error)) throw std::runtime_error(error);
  const std::vector<std::string> segments = RecordLog::read(segments_path, SIZE_MAX, &length);
  for (const std::string& bytes : segments) {
    SavedSegment& s = in.segments.emplace_back();
    if (!decode(bytes, s)) {
      throw std::runtime_error(segments_path + ": record " + std::to_string(in.segments.size()) +
                               " is not a trajectory segment");
    }
    std::string& newest = newest_[s.segment.key_id_first];
    newest_bytes_ += bytes.size() - newest.size();
    newest = bytes;
  }
  segments_bytes_ = length;
  if (!segments_.open_at(segments_path, length, &error)) throw std::runtime_error(error);
  if (in.profiles.empty() && in.segments.empty()) return std::nullopt;
  return in;
}

void MapperStateStore::append(RecordLog& log, const std::string& payload) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!log.append(payload)) ++counters_.write_failures;
  counters_.bytes_appended += static_cast<double>(payload.size() + 12);
  counters_.write_total_s += seconds_since(t0);
}

void MapperStateStore::record(const Profile& profile) {
  append(profiles_, encode(profile, range_quantum_m_));
  ++counters_.profiles_appended;
}

void MapperStateStore::record(const TrajectorySegment& segment, int32_t revision) {
  std::string bytes = encode(segment, revision);
  append(segments_, bytes);
  ++counters_.segments_appended;
  segments_bytes_ += bytes.size() + 12;
  std::string& newest = newest_[segment.key_id_first];
  newest_bytes_ += bytes.size();
  newest_bytes_ -= newest.size();
  newest = std::move(bytes);
  if (segments_bytes_ > 2 * newest_bytes_ + (1u << 20)) compact();
}

void MapperStateStore::compact() {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> records;
  records.reserve(newest_.size());
  std::size_t length = 0;
  for (const auto& [key, bytes] : newest_) {
    records.push_back(bytes);
    length += bytes.size() + 12;
  }
  const std::string path = dir_ + "/segments.rec";
  if (RecordLog::write(path, records) && segments_.open_at(path, length)) {
    segments_bytes_ = length;
    ++counters_.compactions;
  } else {
    ++counters_.write_failures;
  }
  counters_.write_total_s += seconds_since(t0);
}

}  // namespace traverse::mapper
