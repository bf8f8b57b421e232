#include <climits>

#include "type_registry.hpp"

namespace traverse {

const TypeInfo* type_with_fingerprint(uint64_t fingerprint) {
  for (const TypeInfo& t : all_types()) {
    if (t.fingerprint == fingerprint) return &t;
  }
  return nullptr;
}

const TypeInfo* type_of_fingerprint(const void* data, std::size_t size) {
  if (size < 8) return nullptr;
  const auto* b = static_cast<const uint8_t*>(data);
  uint64_t fp = 0;
  for (int i = 0; i < 8; ++i) fp = (fp << 8) | b[i];
  return type_with_fingerprint(fp);
}

const TypeInfo* find_type(const void* data, std::size_t size) {
  const TypeInfo* t = type_of_fingerprint(data, size);
  if (!t || size > static_cast<std::size_t>(INT_MAX)) return nullptr;
  return walk_message(*t->layout, static_cast<const uint8_t*>(data), size).ok() ? t : nullptr;
}

}  // namespace traverse
