#include "export_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <vector>

#include "las_writer.hpp"

namespace traverse::exporter {

namespace {

struct Property {
  std::string name, type;
  std::size_t offset = 0, size = 0;
};

std::size_t type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" ||
      t == "float32") {
    return 4;
  }
  if (t == "double" || t == "float64") return 8;
  return 0;
}

double value(const char* rec, const Property& p) {
  const char* at = rec + p.offset;
  auto get = [at](auto v) {
    std::memcpy(&v, at, sizeof(v));
    return static_cast<double>(v);
  };
  const std::string& t = p.type;
  if (t == "char" || t == "int8") return get(int8_t{});
  if (t == "uchar" || t == "uint8") return get(uint8_t{});
  if (t == "short" || t == "int16") return get(int16_t{});
  if (t == "ushort" || t == "uint16") return get(uint16_t{});
  if (t == "int" || t == "int32") return get(int32_t{});
  if (t == "uint" || t == "uint32") return get(uint32_t{});
  if (t == "float" || t == "float32") return get(float{});
  return get(double{});
}

// PLY writer of the exported cloud (header first with a count patched at the end).
class PlyOut {
 public:
  PlyOut(const std::string& path, const std::string& frame) : f_(path, std::ios::binary) {
    f_ << "ply\nformat binary_little_endian 1.0\n"
       << "comment Traverse cloud: x y z [m] in frame " << frame
       << ", intensity [0..255], time [s] since the Unix epoch, key_id = key pose whose segment "
          "placed the point, red green blue = accuracy colour, loa_level = USIBD level of "
          "accuracy of the 95 % bound, bound95_m [m]\n";
    count_at_ = f_.tellp();
    f_ << "element vertex " << std::string(20, ' ') << "\n"
       << "property float x\nproperty float y\nproperty float z\nproperty uchar intensity\n"
          "property double time\nproperty int key_id\nproperty uchar red\nproperty uchar green\n"
          "property uchar blue\nproperty uchar loa_level\nproperty float bound95_m\nend_header\n";
  }
  void add(const CloudPoint& p, const std::array<uint8_t, 3>& rgb, int level, double bound) {
    char rec[34];
    const float xyz[3] = {static_cast<float>(p.x), static_cast<float>(p.y),
                          static_cast<float>(p.z)};
    std::memcpy(rec, xyz, 12);
    rec[12] = static_cast<char>(static_cast<uint8_t>(std::clamp(p.intensity, 0.0, 255.0)));
    std::memcpy(rec + 13, &p.time_s, 8);
    const int32_t k = static_cast<int32_t>(p.key_id);
    std::memcpy(rec + 21, &k, 4);
    std::memcpy(rec + 25, rgb.data(), 3);
    rec[28] = static_cast<char>(level);
    const float b = static_cast<float>(bound);
    std::memcpy(rec + 29, &b, 4);
    buf_.insert(buf_.end(), rec, rec + 33);
    ++count_;
    if (buf_.size() > (1u << 22)) flush();
  }
  bool close() {
    flush();
    f_.seekp(count_at_);
    std::string line = "element vertex " + std::to_string(count_);
    line.resize(15 + 20, ' ');
    f_ << line;
    f_.close();
    return !f_.fail();
  }

 private:
  void flush() {
    f_.write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
    buf_.clear();
  }
  std::ofstream f_;
  std::streampos count_at_;
  std::vector<char> buf_;
  int64_t count_ = 0;
};

}  // namespace

int64_t read_ply_points(const std::string& path, const std::function<void(const CloudPoint&)>& each,
                        std::string* error) {
  auto fail = [error](const std::string& why) {
    if (error) *error = why;
    return int64_t{-1};
  };
  std::ifstream f(path, std::ios::binary);
  if (!f) return fail("cannot open " + path);
  std::string line;
  std::getline(f, line);
  if (line != "ply") return fail(path + " is not a PLY file");
  int64_t count = -1;
  std::vector<Property> props;
  std::size_t record = 0;
  bool in_vertex = false;
  while (std::getline(f, line) && line != "end_header") {
    std::istringstream in(line);
    std::string word;
    in >> word;
    if (word == "format" && line != "format binary_little_endian 1.0") {
      return fail(path + ": only binary little-endian PLY is read");
    }
    if (word == "element") {
      std::string name;
      in >> name;
      in_vertex = name == "vertex";
      if (in_vertex)
        in >> count;
      else if (count >= 0)
        break;  // only a leading vertex element is read
    }
    if (word == "property" && in_vertex) {
      Property p;
      in >> p.type >> p.name;
      p.size = type_size(p.type);
      if (p.size == 0) return fail(path + ": unsupported property '" + line + "'");
      p.offset = record;
      record += p.size;
      props.push_back(p);
    }
  }
  const Property *x = nullptr, *y = nullptr, *z = nullptr, *intensity = nullptr, *time = nullptr,
                 *key = nullptr;
  for (const Property& p : props) {
    if (p.name == "x") x = &p;
    if (p.name == "y") y = &p;
    if (p.name == "z") z = &p;
    if (p.name == "intensity") intensity = &p;
    if (p.name == "time") time = &p;
    if (p.name == "key_id") key = &p;
  }
  if (count < 0 || !x || !y || !z) return fail(path + ": no vertex element with x, y, z");
  std::vector<char> buf(record * 65536);
  int64_t done = 0;
  while (done < count) {
    const int64_t n = std::min<int64_t>(65536, count - done);
    if (!f.read(buf.data(), static_cast<std::streamsize>(n * record))) {
      return fail(path + ": file shorter than its header says (" + std::to_string(done) + " of " +
                  std::to_string(count) + " points)");
    }
    for (int64_t i = 0; i < n; ++i) {
      const char* rec = buf.data() + i * record;
      CloudPoint p{value(rec, *x),
                   value(rec, *y),
                   value(rec, *z),
                   intensity ? value(rec, *intensity) : 0.0,
                   time ? value(rec, *time) : 0.0,
                   key ? static_cast<int64_t>(value(rec, *key)) : -1};
      each(p);
    }
    done += n;
  }
  return count;
}

PointBounds::PointBounds(const RunEstimate& run) {
  auto bound_of = [&run](int64_t id) {
    auto it = run.key_poses.find(id);
    return it == run.key_poses.end() ? std::numeric_limits<double>::infinity()
                                     : bound95_m(it->second.covariance);
  };
  for (const auto& [first, seg] : run.segments) {
    if (seg.utime.empty()) continue;
    by_first_[first] = {static_cast<double>(seg.utime.front()) * 1e-6,
                        static_cast<double>(seg.utime.back()) * 1e-6, bound_of(seg.key_id_first),
                        bound_of(seg.key_id_last)};
  }
}

double PointBounds::at(int64_t key_id, double time_s) const {
  auto it = by_first_.find(key_id);
  if (it == by_first_.end()) return std::numeric_limits<double>::infinity();
  const Span& s = it->second;
  const double span = s.t1 - s.t0;
  const double u = span > 0 ? std::clamp((time_s - s.t0) / span, 0.0, 1.0) : 0.0;
  return (1 - u) * s.b0 + u * s.b1;
}

std::string local_frame_wkt(const std::string& frame) {
  return "LOCAL_CS[\"traverse " + frame + "\",LOCAL_DATUM[\"traverse " + frame +
         "\",0],UNIT[\"metre\",1],AXIS[\"X\",OTHER],AXIS[\"Y\",OTHER],AXIS[\"Z\",UP]]";
}

bool export_cloud(const std::string& ply_in, const RunEstimate& run, const CloudOptions& o,
                  CloudSummary* summary, std::string* error) {
  const PointBounds bounds(run);
  std::unique_ptr<LasWriter> las;
  if (!o.las_path.empty()) {
    las = std::make_unique<LasWriter>(
        o.las_path, local_frame_wkt(o.frame),
        std::vector<LasExtraField>{
            {"loa_level", LasExtraField::Type::kU8, "USIBD LOA of the 95% bound"},
            {"bound95_m", LasExtraField::Type::kF32, "95% position bound [m]"},
            {"key_id", LasExtraField::Type::kF32, "key pose of the point"}},
        "traverse-export");
    if (!las->good()) {
      if (error) *error = las->error();
      return false;
    }
  }
  std::unique_ptr<PlyOut> ply;
  if (!o.ply_path.empty()) ply = std::make_unique<PlyOut>(o.ply_path, o.frame);
  CloudSummary s;
  const Eigen::Matrix2d R = o.T_out_map.rotation();
  const Eigen::Vector2d t = o.T_out_map.translation();
  bool ok = true;
  const int64_t n = read_ply_points(
      ply_in,
      [&](const CloudPoint& in) {
        if (!ok || s.read++ % o.thin_every != 0) return;
        CloudPoint p = in;
        const Eigen::Vector2d xy = R * Eigen::Vector2d(in.x, in.y) + t;
        p.x = xy.x();
        p.y = xy.y();
        const double b = bounds.at(in.key_id, in.time_s);
        const int level = loa_level(b);
        const auto rgb = level_colour(level, o.top_level, o.bottom_level);
        ++s.points_per_level[level];
        ++s.written;
        if (ply) ply->add(p, rgb, level, b);
        if (las) {
          LasPoint q{p.x,
                     p.y,
                     p.z,
                     static_cast<uint16_t>(std::clamp(p.intensity, 0.0, 255.0) * 257),
                     p.time_s,
                     static_cast<uint16_t>(rgb[0] * 257),
                     static_cast<uint16_t>(rgb[1] * 257),
                     static_cast<uint16_t>(rgb[2] * 257),
                     0,
                     {static_cast<double>(level), std::isfinite(b) ? b : -1.0,
                      static_cast<double>(p.key_id)}};
          ok = las->add(q);
        }
      },
      error);
  if (n < 0) return false;
  if (las && !las->close()) ok = false;
  if (!ok) {
    if (error) *error = las->error();
    return false;
  }
  if (ply && !ply->close()) {
    if (error) *error = "cannot write " + o.ply_path;
    return false;
  }
  if (summary) *summary = s;
  return true;
}

}  // namespace traverse::exporter
