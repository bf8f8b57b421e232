// The mapper's state on disk, so that a mapper killed mid-run and restarted by the launcher, or a
// mapping session stopped and started again later, goes on with the same cloud and OctoMap
// instead of an empty one (docs/deployment.md, "Crash recovery and sessions").
//
// What is kept is what the map is made from, not the map: the cloud and the OctoMap are a
// function of the profiles and the newest version of each trajectory segment (mapper.hpp: a
// moved segment's profiles are placed again), so replaying those into a new Mapper gives the same
// map, voxel for voxel. A state directory holds two append-only record logs (state_file.hpp):
//   - profiles.rec: every profile as it came, its ranges quantised as the mapper stores them
//     (16 bits over [0, range_max_m]: the points are placed exactly where the mapper places them)
//     and its 8-bit intensities, about 3 bytes a beam; a profile never changes, so it is written
//     once;
//   - segments.rec: every trajectory segment taken (with its revision); a moved segment is
//     appended again. When the log holds more than twice the bytes of the newest versions (plus
//     1 MB), it is rewritten with only those, atomically, so it stays within about twice the
//     trajectory's size however many loop closures move it.
// Each record is appended as its message is taken, with one write(): a SIGKILL loses nothing
// written, and a record torn by a crash mid-write is cut off on reading. (A power cut may lose
// what the kernel had not yet written; the logs are not flushed to the disk record by record.)
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mapper.hpp"
#include "state_file.hpp"

namespace traverse::mapper {

struct MapperStateCounters {
  long profiles_appended = 0;
  long segments_appended = 0;
  long compactions = 0;
  long write_failures = 0;      // appends or compactions that failed (the state is then stale)
  double write_total_s = 0.0;   // [s] wall time spent writing records and compacting
  double bytes_appended = 0.0;  // [bytes] written since the start
};

// A segment as it was taken, with the revision the densifier gave it (0 from a pose stream).
struct SavedSegment {
  TrajectorySegment segment;
  int32_t revision = 0;
};

// What a state directory held, in the order it came.
struct SavedInputs {
  std::vector<SavedSegment> segments;
  std::vector<Profile> profiles;
};

class MapperStateStore {
 public:
  // Keeps the state in `dir` (created if missing); profiles' ranges quantised over
  // [0, range_max_m].
  MapperStateStore(std::string dir, double range_max_m);

  // Reads what `dir` holds and opens its logs for appending after it. nullopt when it holds
  // nothing; throws std::runtime_error naming the file when a record cannot be decoded (the mapper
  // must not go on as if it had no state).
  std::optional<SavedInputs> load();
  void record(const Profile& profile);
  void record(const TrajectorySegment& segment, int32_t revision);

  const MapperStateCounters& counters() const { return counters_; }
  const std::string& dir() const { return dir_; }

 private:
  void append(RecordLog& log, const std::string& payload);
  void compact();

  std::string dir_;
  double range_quantum_m_;
  RecordLog profiles_, segments_;
  // The newest version of each segment, encoded, by key_id_first (for compaction).
  std::map<int64_t, std::string> newest_;
  std::size_t newest_bytes_ = 0, segments_bytes_ = 0;
  MapperStateCounters counters_;
};

}  // namespace traverse::mapper
