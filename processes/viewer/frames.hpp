// What goes to a browser over the WebSocket (the page's viewer.js reads it): text frames of JSON
// for everything small, binary frames for points, little-endian:
//   profiles (kind 1): u8 1, u32 count, then per profile: f64 utime [us], u32 index, f32 x [m],
//     f32 y [m], f32 theta [rad] (T_map_base it is drawn with), u32 n, n x (i16 x, y, z) [mm] in
//     the base frame (the page places them: p_map = R(theta) p_base + (x, y));
//   poses (kind 2): u8 2, u32 count, then per profile: u32 index, f32 x, f32 y, f32 theta.
// JSON frames carry "type": "reset" (a snapshot follows: forget everything), "legend",
// "annotations", "trajectory", "pose", "status", "guidance", "view" (how to draw: the voxels'
// edge, how often the page redraws what the feed changed). A snapshot is "reset" followed by the
// whole state in the same frames as the changes, so the page has one way to read either.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "guidance.hpp"
#include "scene.hpp"
#include "status_board.hpp"

namespace traverse::viewer {

struct Frame {
  std::shared_ptr<const std::string> data;
  bool binary = false;
  std::size_t size() const { return data ? data->size() : 0; }
};

// Binary frames are cut at about this size, so one frame never holds a browser's socket for long.
inline constexpr std::size_t kFrameBytes = 1 << 20;

// The frames that bring a page up to date with `changes`.
std::vector<Frame> encode_changes(const Scene& scene, const Changes& changes);
// "reset" and the whole scene.
std::vector<Frame> encode_snapshot(const Scene& scene);
Frame encode_status(const StatusBoard& board, int64_t now_utime);
Frame encode_guidance(const Guidance& guidance);
// How the page draws what it gets: the edge of its voxels [m].
Frame encode_view(double voxel_m, double redraw_period_s);

}  // namespace traverse::viewer
