// What an encoded LCM message must hold, checked before it is decoded.
//
// The decoders lcm-gen writes allocate every array a message claims before checking that the
// message holds it: an 81-byte planar_scan_t claiming 100 M ranges costs 400 MB before the
// decode fails, a negative length throws, and twenty status messages claiming 5 M channels each
// kept the monitor busy for 23 s. Here the bytes are walked along the type's layout instead --
// every string length and array size read and checked against the bytes left, nothing allocated
// -- so that only a message that holds everything it claims reaches the decoder, which then
// allocates at most a small multiple of the message's size (a std::string or an element of a
// nested array costs a few dozen bytes of memory per byte of message at worst).
//
// The layouts come from lcm-gen's own parse of lcmtypes/*.lcm (`lcm-gen -d`, run by
// cmake/lcmtypes.cmake), so a new type needs no code here. LCM's encoding: an 8-byte fingerprint,
// then each field in order, big-endian; a string is an int32 length counting its terminating NUL,
// then the bytes; an array is its elements one after another, its sizes given by constants or by
// integer fields earlier in the same struct; a nested struct has no fingerprint of its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace traverse {

struct StructLayout;

struct FieldLayout {
  enum class Kind { kPrimitive, kString, kStruct };
  struct Dim {
    int64_t size = 0;    // a constant size, when var_field < 0
    int var_field = -1;  // else the index of the integer field (same struct) holding the size
  };
  std::string name;
  Kind kind = Kind::kPrimitive;
  int primitive_bytes = 0;             // kPrimitive: 1, 2, 4 or 8
  bool is_integer = false;             // kPrimitive: an integer type (may size an array)
  std::string type_name;               // e.g. "int32_t", "string", "traverse.channel_stats_t"
  const StructLayout* type = nullptr;  // kStruct
  std::vector<Dim> dims;               // empty for a single value
};

struct StructLayout {
  std::string name;  // e.g. "traverse.planar_scan_t"
  std::vector<FieldLayout> fields;
  int64_t min_bytes = 0;  // the fewest bytes an element of this struct takes (no fingerprint)
};

class LayoutSet {
 public:
  // Parses the output of `lcm-gen -d` on a set of .lcm files; throws std::runtime_error naming
  // the line when it cannot (a type it does not know, a size field that does not precede it).
  static LayoutSet parse(std::string_view lcm_gen_debug_text);

  const StructLayout* find(std::string_view type_name) const;
  const std::vector<std::unique_ptr<StructLayout>>& types() const { return types_; }

 private:
  std::vector<std::unique_ptr<StructLayout>> types_;
};

// A cap on an array's length beyond what the bytes allow (a scan's beam count, say).
struct ArrayLimit {
  std::string type;   // "traverse.planar_scan_t"
  std::string field;  // "ranges"
  int64_t max_elements = 0;
};

struct WalkResult {
  enum class Outcome { kOk, kMalformed, kOverLimit };
  Outcome outcome = Outcome::kMalformed;
  std::string problem;  // why not ok, e.g. "ranges claims 100000000 elements, 53 bytes left"
  bool ok() const { return outcome == Outcome::kOk; }
};

// Walks a whole encoded message (fingerprint first, not compared here) of type `layout`: ok when
// every length it claims is non-negative and held by the bytes, no array exceeds `limits`, and the
// message ends exactly at `size`. Time is linear in the number of strings and struct elements the
// message holds, memory constant.
WalkResult walk_message(const StructLayout& layout, const uint8_t* data, std::size_t size,
                        const std::vector<ArrayLimit>& limits = {});

}  // namespace traverse
