// Fuzz target: the LCM log reader, and the checks traverse-validate runs on every event it reads.
// Invariants: events and damage come in file order, and never cover more bytes than the file.
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "lcm_log.hpp"
#include "stream_analyzer.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;  // fmemopen refuses an empty buffer
  std::FILE* f = fmemopen(const_cast<uint8_t*>(data), size, "rb");
  if (!f) return 0;
  traverse::LogReader reader(f);
  traverse::validate::StreamAnalyzer analyzer;
  uint64_t covered = 0, last_offset = 0;
  bool first = true;
  while (auto ev = reader.next()) {
    if (!first && ev->offset <= last_offset) std::abort();
    first = false;
    last_offset = ev->offset;
    covered += 28 + ev->channel.size() + ev->data.size();
    analyzer.add(ev->channel, ev->utime, ev->data.data(), ev->data.size());
  }
  for (const traverse::LogDamage& d : reader.damage()) covered += d.skipped_bytes;
  if (covered != size) std::abort();  // every byte is either an event or skipped damage
  analyzer.summary();
  return 0;
}
