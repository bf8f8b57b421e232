#include "type_registry.hpp"

namespace traverse {

const TypeInfo* find_type(const void* data, std::size_t size) {
  if (size < 8) return nullptr;
  const auto* b = static_cast<const uint8_t*>(data);
  uint64_t fp = 0;
  for (int i = 0; i < 8; ++i) fp = (fp << 8) | b[i];
  for (const TypeInfo& t : all_types()) {
    if (t.fingerprint == fp) return &t;
  }
  return nullptr;
}

}  // namespace traverse
