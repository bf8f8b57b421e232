// All message types of package traverse, by LCM fingerprint (generated from lcmtypes/ at build).
// Lets tools that see raw bytes (log validation) tell which type a message claims to be and
// whether it decodes as that type.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace traverse {

struct TypeInfo {
  std::string name;       // e.g. "traverse.planar_scan_t"
  uint64_t fingerprint;   // first 8 bytes of every encoded message, big-endian
  bool (*decodes)(const void* data, int size);  // true when the bytes decode completely
};

const std::vector<TypeInfo>& all_types();

// The type whose fingerprint starts `data`, or nullptr (too short or unknown fingerprint).
const TypeInfo* find_type(const void* data, std::size_t size);

}  // namespace traverse
