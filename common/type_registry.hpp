// All message types of package traverse, by LCM fingerprint (generated from lcmtypes/ at build).
// Lets tools that see raw bytes (log validation) tell which type a message claims to be and
// whether it decodes as that type.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace traverse {

// What a decoded message says about itself, found by field name so that a new type with the
// usual fields needs no code: utime, seq, n_ranges, utime_first/utime_last, frame,
// parent_frame/child_frame. Fields the type does not have stay empty.
struct MessageFacts {
  std::optional<int64_t> utime;     // [us] the message's own time
  std::optional<int64_t> seq;       // per-channel sequence number
  std::optional<int64_t> points;    // points (beams) in the message
  std::optional<int64_t> sweep_us;  // [us] utime_last - utime_first
  std::string frame;                // `frame`, or "parent_frame->child_frame"
};

struct TypeInfo {
  std::string name;       // e.g. "traverse.planar_scan_t"
  uint64_t fingerprint;   // first 8 bytes of every encoded message, big-endian
  bool (*decodes)(const void* data, int size);  // true when the bytes decode completely
  // Like decodes(), and on success fills `facts`.
  bool (*inspect)(const void* data, int size, MessageFacts& facts);
};

const std::vector<TypeInfo>& all_types();

// The type whose fingerprint starts `data`, or nullptr (too short or unknown fingerprint).
const TypeInfo* find_type(const void* data, std::size_t size);

}  // namespace traverse
