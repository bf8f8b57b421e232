// A decimated preview of the growing cloud for screens (traverse-viewer, issue 26): the full cloud
// grows by 244,000 points/s, which no browser draws for long, while a screen needs about one point
// per few centimetres of surface. Of every profile first placed, the preview keeps the points that
// fall in a cell of a cell_m grid no earlier point fell in, so the preview grows with the surface
// mapped, not with time (a pass over mapped ground adds almost nothing).
//
// The kept points are expressed in the base frame at the profile's first beam time, as the mapper
// placed them (de-skew included), so a viewer places each profile with one pose of the corrected
// trajectory and moves it when a loop closure moves that pose: the mapper never sends a point
// twice and places every point in one place. (A profile lasts 33 ms, during which a loop closure
// changes the relative motion by far less than a millimetre.) The grid's cells are those of the
// first placement and are not updated when a closure moves points: they only choose which points
// are kept.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_set>
#include <vector>

#include "se2.hpp"

namespace traverse::mapper {

struct PreviewConfig {
  std::string channel = "CLOUD_PREVIEW";  // cloud_preview_t; "": no preview
  double cell_m = 0.05;                   // [m] edge of the grid's cells: one point per cell
  int max_points_per_message = 9000;      // 6 bytes each: a message stays under 64 KB
  // [bytes] what the mapper keeps of the preview to answer a late viewer (preview_resend.hpp):
  // beyond it the kept points are thinned to a coarser grid, so memory follows the map's extent,
  // not the run's length. 8 MiB: about 1.3 million points. At most 16 GiB (a thinning pass numbers
  // the points kept in 32 bits).
  int64_t resend_max_bytes = 8 << 20;

  template <class V>
  void visit(V& v) {
    v("channel", channel);
    v("cell_m", cell_m);
    v("max_points_per_message", max_points_per_message);
    v("resend_max_bytes", resend_max_bytes);
  }
};

// The first value out of range, named by its key; nullopt when the config is usable.
std::optional<std::string> validate(const PreviewConfig& config);

struct PreviewProfile {
  int64_t utime = 0;                              // [us] the profile's first beam
  std::vector<std::array<int16_t, 3>> p_base_mm;  // [mm] base frame at utime
  Pose2 T_world_base;  // the pose it was first placed with (chooses cells, is not sent)
};

// The cell of a grid of edge cell_m [m] that holds world point (x, y, z) [m], packed into 63 bits
// (21 per axis: 2^20 cells either side of the origin); nullopt outside that range.
std::optional<uint64_t> preview_cell(double x, double y, double z, double cell_m);
// The cell of the grid of edge 2 cell_m that holds the whole of `cell` (a preview_cell() at
// cell_m): the same as preview_cell() of any of its points at 2 cell_m, from the indices alone.
uint64_t preview_cell_doubled(uint64_t cell);

// Thread-safe: add() on the mapper's thread, take() on the publishing one.
class CloudPreview {
 public:
  explicit CloudPreview(const PreviewConfig& config);

  // A profile first placed (Mapper::on_first_placement): keeps its points in new cells.
  void add(int64_t utime, const Pose2& T_world_base, const std::vector<Eigen::Vector3f>& p_world);
  // The profiles kept since the last call, in groups of at most max_points_per_message points (a
  // profile with more is split into several entries of the same utime).
  std::vector<std::vector<PreviewProfile>> take();

  int64_t points() const;  // kept so far
  int64_t cells() const;   // cells filled (each holds one kept point)

 private:
  PreviewConfig config_;
  mutable std::mutex mutex_;
  std::unordered_set<uint64_t> cells_;  // packed 21-bit cell indices
  std::vector<PreviewProfile> pending_;
  int64_t points_ = 0;
};

}  // namespace traverse::mapper
