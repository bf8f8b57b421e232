#include "frames.hpp"

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

namespace traverse::viewer {
namespace {

using nlohmann::json;

Frame text(const json& j) { return {std::make_shared<const std::string>(j.dump()), false}; }

// [m] rounded to a millimetre: the page needs no more, and the JSON stays short.
double mm(double v) { return std::round(v * 1000.0) / 1000.0; }

template <class T>
void put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));  // little-endian hosts only (x86, ARM as Debian runs them)
  out.append(b, sizeof(T));
}

// Binary frames of `kind`, each an u32 count and then records written by `write(out, index)`.
template <class Write>
std::vector<Frame> binary(uint8_t kind, const std::vector<uint32_t>& indices, Write write) {
  std::vector<Frame> frames;
  std::string out;
  uint32_t count = 0;
  auto flush = [&] {
    if (count == 0) return;
    std::memcpy(out.data() + 1, &count, sizeof(count));
    frames.push_back({std::make_shared<const std::string>(std::move(out)), true});
    out.clear();
    count = 0;
  };
  for (uint32_t i : indices) {
    if (count == 0) {
      put(out, kind);
      put(out, uint32_t{0});  // count, filled in by flush
    }
    write(out, i);
    ++count;
    if (out.size() >= kFrameBytes) flush();
  }
  flush();
  return frames;
}

void put_pose(std::string& out, const Pose2& T) {
  put(out, static_cast<float>(T.x()));
  put(out, static_cast<float>(T.y()));
  put(out, static_cast<float>(T.theta()));
}

std::vector<Frame> profiles(const Scene& scene, const std::vector<uint32_t>& indices) {
  return binary(1, indices, [&scene](std::string& out, uint32_t i) {
    const Profile& p = scene.profiles()[i];
    put(out, static_cast<double>(p.utime));
    put(out, i);
    put_pose(out, p.T_map_base);
    put(out, static_cast<uint32_t>(p.p_base_mm.size()));
    for (const auto& q : p.p_base_mm) {
      for (int16_t v : q) put(out, v);
    }
  });
}

std::vector<Frame> poses(const Scene& scene, const std::vector<uint32_t>& indices) {
  return binary(2, indices, [&scene](std::string& out, uint32_t i) {
    put(out, i);
    put_pose(out, scene.profiles()[i].T_map_base);
  });
}

json legend_json(const Legend& l) {
  json levels = json::array();
  for (const LegendLevel& v : l.levels) {
    levels.push_back({{"name", v.name},
                      {"min_m", v.min_m},
                      {"max_m", std::isfinite(v.max_m) ? json(v.max_m) : json(nullptr)},
                      {"rgb", {v.rgb[0], v.rgb[1], v.rgb[2]}},
                      {"accepted", v.accepted}});
  }
  return {{"type", "legend"},
          {"standard", l.standard},
          {"coloured_by", l.coloured_by},
          {"bound_method", l.bound_method},
          {"confidence", l.confidence},
          {"best_level", l.best_level},
          {"worst_level", l.worst_level},
          {"levels", levels}};
}

Frame annotations(const Scene& scene, const std::vector<int64_t>& ids) {
  json keys = json::array();
  for (int64_t id : ids) {
    const KeyAnnotation& k = scene.annotations().at(id);
    // [id, utime us, x m, y m, level, bound m, local bound m]
    keys.push_back({k.id, k.utime, mm(k.x), mm(k.y), k.level, mm(k.bound_m), mm(k.local_bound_m)});
  }
  return text({{"type", "annotations"}, {"keys", keys}});
}

Frame trajectory(const Scene& scene, const std::vector<int64_t>& ids) {
  json segments = json::array();
  for (int64_t id : ids) {
    const Polyline& p = scene.polylines().at(id);
    json xy = json::array();
    for (const auto& q : p.xy) {
      xy.push_back(mm(q[0]));
      xy.push_back(mm(q[1]));
    }
    segments.push_back({{"id", p.key_id_first}, {"rev", p.revision}, {"xy", xy}});
  }
  return text({{"type", "trajectory"}, {"segments", segments}});
}

std::optional<Frame> pose(const Scene& scene) {
  const auto now = scene.current_pose();
  if (!now) return std::nullopt;
  return text({{"type", "pose"},
               {"utime", now->utime},
               {"x", mm(now->T_map_base.x())},
               {"y", mm(now->T_map_base.y())},
               {"theta", std::round(now->T_map_base.theta() * 1e4) / 1e4}});
}

void append(std::vector<Frame>& out, std::vector<Frame> more) {
  out.insert(out.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
}

}  // namespace

std::vector<Frame> encode_changes(const Scene& scene, const Changes& c) {
  std::vector<Frame> out;
  if (c.legend && scene.legend()) out.push_back(text(legend_json(*scene.legend())));
  if (!c.annotations.empty()) out.push_back(annotations(scene, c.annotations));
  if (!c.segments.empty()) out.push_back(trajectory(scene, c.segments));
  append(out, profiles(scene, c.new_profiles));
  append(out, poses(scene, c.moved_profiles));
  if (c.pose) {
    if (auto f = pose(scene)) out.push_back(*f);
  }
  return out;
}

std::vector<Frame> encode_snapshot(const Scene& scene) {
  Changes all;
  all.legend = true;
  all.pose = true;
  for (const auto& [id, k] : scene.annotations()) all.annotations.push_back(id);
  for (const auto& [id, p] : scene.polylines()) all.segments.push_back(id);
  for (uint32_t i = 0; i < scene.profiles().size(); ++i) {
    if (scene.profiles()[i].placed) all.new_profiles.push_back(i);
  }
  std::vector<Frame> out{text({{"type", "reset"}})};
  append(out, encode_changes(scene, all));
  return out;
}

Frame encode_status(const StatusBoard& board, int64_t now_utime) {
  json rows = json::array();
  for (const auto& [name, r] : board.rows()) {
    const StatusReport& s = r.last;
    rows.push_back({{"process", s.process},
                    {"host", s.host},
                    {"state", s.state},
                    {"stale", r.stale},
                    {"age_s", std::round((now_utime - s.utime) * 1e-5) / 10.0},
                    {"uptime_s", std::round(s.uptime_s)},
                    {"cpu_percent", std::round(r.cpu_percent * 10) / 10},
                    {"rss_mb", std::round(s.rss_bytes / 1e5) / 10},
                    {"in_hz", std::round(r.in_hz * 10) / 10},
                    {"out_hz", std::round(r.out_hz * 10) / 10},
                    {"missed", s.missed},
                    {"dropped", s.queue_dropped},
                    {"rejected", s.rejected + s.decode_failures + s.out_of_order},
                    {"errors", s.handler_errors}});
  }
  return text({{"type", "status"}, {"processes", rows}});
}

Frame encode_guidance(const Guidance& g) {
  auto target = [](const GuidanceTarget& t) {
    return json{{"id", t.id}, {"x", mm(t.x)}, {"y", mm(t.y)}, {"distance_m", mm(t.distance_m)}};
  };
  json below = json::array();
  for (const auto& r : g.below) {
    if (!r) {
      below.push_back(nullptr);
      continue;
    }
    json j = target(r->nearest);
    j["first_id"] = r->first_id;
    j["last_id"] = r->last_id;
    j["keys"] = r->keys;
    below.push_back(j);
  }
  return text({{"type", "guidance"},
               {"utime", g.utime},
               {"below", below},
               {"loop_target", g.loop_target ? target(*g.loop_target) : json(nullptr)}});
}

Frame encode_view(double voxel_m, double redraw_period_s) {
  return text({{"type", "view"}, {"voxel_m", voxel_m}, {"redraw_period_s", redraw_period_s}});
}

}  // namespace traverse::viewer
