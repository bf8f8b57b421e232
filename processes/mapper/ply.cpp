#include "ply.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

namespace traverse::mapper {

namespace {

constexpr std::size_t kRecord = 3 * 4 + 1 + 8 + 4 + 3 + 1;  // bytes per point
const char* const kProperties =
    "property float x\nproperty float y\nproperty float z\nproperty uchar intensity\n"
    "property double time\nproperty int key_id\nproperty uchar red\nproperty uchar green\n"
    "property uchar blue\nproperty char level\n";

void encode(const CloudPoint& p, char* out) {
  std::memcpy(out, p.p_world.data(), 12);
  out[12] = static_cast<char>(p.intensity);
  const double t = static_cast<double>(p.utime) * 1e-6;
  std::memcpy(out + 13, &t, 8);
  const int32_t k = static_cast<int32_t>(p.key_id);
  std::memcpy(out + 21, &k, 4);
  std::memcpy(out + 25, p.colour.rgb.data(), 3);
  out[28] = static_cast<char>(p.colour.level);
}

}  // namespace

bool write_ply(const std::string& path, int64_t count,
               const std::function<void(const std::function<void(const CloudPoint&)>&)>& each) {
  std::ofstream f(path, std::ios::binary);
  if (!f) return false;
  f << "ply\nformat binary_little_endian 1.0\n"
    << "comment Traverse cloud: x y z [m] in frame map (the base at the first scan, or the "
       "frontend's initial_pose), intensity [0..255], time [s] since the Unix epoch, key_id = "
       "key pose whose segment placed the point, red green blue level = accuracy colour and "
       "level of the annotations (-1: none)\n"
    << "element vertex " << count << "\n"
    << kProperties << "end_header\n";
  std::vector<char> buf;
  buf.reserve(kRecord * 65536);
  int64_t written = 0;
  each([&](const CloudPoint& p) {
    buf.resize(buf.size() + kRecord);
    encode(p, buf.data() + buf.size() - kRecord);
    ++written;
    if (buf.size() >= kRecord * 65536) {
      f.write(buf.data(), static_cast<std::streamsize>(buf.size()));
      buf.clear();
    }
  });
  f.write(buf.data(), static_cast<std::streamsize>(buf.size()));
  return static_cast<bool>(f) && written == count;
}

bool write_ply(const std::string& path, const Mapper& mapper, const PointColours* colours) {
  return write_ply(path, mapper.placed_points(),
                   [&](const std::function<void(const CloudPoint&)>& f) {
                     if (!colours) return mapper.for_each_point(f);
                     mapper.for_each_point([&](const CloudPoint& p) {
                       CloudPoint coloured = p;
                       coloured.colour = colours->at(p.utime);
                       f(coloured);
                     });
                   });
}

std::optional<std::vector<CloudPoint>> read_ply(const std::string& path, std::string* error) {
  auto fail = [error](const std::string& why) -> std::optional<std::vector<CloudPoint>> {
    if (error) *error = why;
    return std::nullopt;
  };
  std::ifstream f(path, std::ios::binary);
  if (!f) return fail("cannot open " + path);
  std::string line, props;
  int64_t count = -1;
  std::getline(f, line);
  if (line != "ply") return fail(path + " is not a PLY file");
  while (std::getline(f, line) && line != "end_header") {
    if (line.rfind("element vertex ", 0) == 0) count = std::stoll(line.substr(15));
    if (line.rfind("property ", 0) == 0) props += line + "\n";
    if (line.rfind("format ", 0) == 0 && line != "format binary_little_endian 1.0") {
      return fail(path + ": only binary little-endian PLY is read");
    }
  }
  if (count < 0 || props != kProperties) return fail(path + ": not a Traverse cloud layout");
  std::vector<CloudPoint> out(static_cast<std::size_t>(count));
  char rec[kRecord];
  for (CloudPoint& p : out) {
    if (!f.read(rec, kRecord)) return fail(path + ": file shorter than its header says");
    std::memcpy(p.p_world.data(), rec, 12);
    p.intensity = static_cast<uint8_t>(rec[12]);
    double t;
    std::memcpy(&t, rec + 13, 8);
    p.utime = std::llround(t * 1e6);
    int32_t k;
    std::memcpy(&k, rec + 21, 4);
    p.key_id = k;
    std::memcpy(p.colour.rgb.data(), rec + 25, 3);
    p.colour.level = static_cast<int8_t>(rec[28]);
  }
  return out;
}

}  // namespace traverse::mapper
