// All message types of package traverse, by LCM fingerprint (generated from lcmtypes/ at build).
// Lets tools that see raw bytes (log validation, the monitor, the evaluator) tell which type a
// message claims to be, whether its bytes hold what it claims (message_layout.hpp: checked before
// anything is allocated) and whether what it says can be right (message_checks.hpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "message_layout.hpp"

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

// How a message fared, worst first.
enum class MessageVerdict {
  kMalformed,    // its bytes do not hold what it claims (or do not decode): not decoded
  kOverLimit,    // an array longer than a limit (a scan's beam cap): not decoded
  kImplausible,  // decodes, but what it says cannot be right (a zero angle step)
  kGood,
};

struct Inspection {
  MessageVerdict verdict = MessageVerdict::kMalformed;
  std::string problem;  // why not good
  MessageFacts facts;   // filled when the message decoded (good or implausible)
  bool good() const { return verdict == MessageVerdict::kGood; }
};

struct TypeInfo {
  std::string name;                      // e.g. "traverse.planar_scan_t"
  uint64_t fingerprint = 0;              // first 8 bytes of every encoded message, big-endian
  const StructLayout* layout = nullptr;  // from lcm-gen's parse of the type
  // Walks the bytes, decodes them when they hold what they claim, checks plausibility.
  Inspection (*inspect)(const void* data, int size,
                        const std::vector<ArrayLimit>& limits) = nullptr;
};

const std::vector<TypeInfo>& all_types();

// The type whose fingerprint starts `data`, or nullptr (too short or unknown fingerprint).
const TypeInfo* type_of_fingerprint(const void* data, std::size_t size);
const TypeInfo* type_with_fingerprint(uint64_t fingerprint);

// The type `data` is a well-formed message of: its fingerprint is known and its bytes hold every
// string and array they claim (walked without allocating anything); nullptr otherwise. Decoding
// the bytes as that type then succeeds and allocates at most a small multiple of `size`.
const TypeInfo* find_type(const void* data, std::size_t size);

}  // namespace traverse
