// ASPRS LAS 1.4 (R15) writer for point clouds, point data record format 7: X, Y, Z, intensity,
// GPS time and RGB, plus "extra bytes" described in the file (an Extra Bytes VLR), and the
// frame named in an OGC WKT coordinate system VLR (a local engineering frame; LAS 1.4 requires
// WKT for formats 6 to 10). No Debian package offers a LAS writer library (libLAS and PDAL are not
// in Debian 12), so the format is written here, from the specification.
//
// Coordinates are stored as int32 counts of `scale_m` from an offset chosen from the first point
// (so any site up to +-214 km at 0.1 mm fits). Times are written as adjusted standard GPS time
// (GPS seconds minus 1e9; global encoding bit 0), converted from the Unix times Traverse uses.
// The header's counts and bounds are written when the file is closed.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace traverse {

// One extra per-point value, stored after the standard fields in the order declared.
struct LasExtraField {
  enum class Type : uint8_t { kU8 = 1, kU16 = 3, kF32 = 9 };  // LAS extra-bytes data types
  std::string name;                                           // up to 31 characters
  Type type = Type::kU8;
  std::string description;  // up to 31 characters
};

struct LasPoint {
  double x = 0, y = 0, z = 0;             // [m] in the file's frame
  uint16_t intensity = 0;                 // [0..65535]
  double unix_time_s = 0;                 // [s] since the Unix epoch (written as adjusted GPS time)
  uint16_t red = 0, green = 0, blue = 0;  // [0..65535]
  uint8_t classification = 0;             // ASPRS class (0: created, never classified)
  std::vector<double> extra;              // one value per declared extra field, in declared order
};

// Seconds since the Unix epoch -> adjusted standard GPS time (GPS seconds - 1e9), with the 18 leap
// seconds GPS time has been ahead of UTC since 2017.
double unix_to_adjusted_gps(double unix_time_s);

class LasWriter {
 public:
  // `frame_wkt`: the frame as OGC WKT (e.g. a LOCAL_CS naming it); `software`: up to 31 chars.
  LasWriter(std::string path, std::string frame_wkt, std::vector<LasExtraField> extra,
            std::string software, double scale_m = 1e-4);
  ~LasWriter();
  LasWriter(const LasWriter&) = delete;
  LasWriter& operator=(const LasWriter&) = delete;

  bool good() const { return file_ != nullptr && ok_; }
  const std::string& error() const { return error_; }
  // Appends a point (extra.size() must match the declared fields; false and error() if not).
  bool add(const LasPoint& p);
  // Writes the header's counts and bounds and closes the file; false on any write error.
  bool close();
  uint64_t points() const { return count_; }
  int record_length() const { return record_length_; }

 private:
  bool write_header();
  bool fail(const std::string& why);

  std::string path_, wkt_, software_;
  std::vector<LasExtraField> extra_;
  double scale_;
  std::FILE* file_ = nullptr;
  bool ok_ = true;
  std::string error_;
  uint64_t count_ = 0;
  bool have_offset_ = false;
  std::array<double, 3> offset_{}, min_{}, max_{};
  int record_length_ = 0;
  uint32_t point_offset_ = 0;
  std::vector<char> buffer_;
};

}  // namespace traverse
