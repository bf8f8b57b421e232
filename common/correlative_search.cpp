#include "correlative_search.hpp"

#include <algorithm>
#include <cstddef>

namespace traverse::correlative {

// Separably, the largest of k cells towards +i, then of k of those towards +j; each pass runs
// over whole rows (a row against the row shifted by one cell, or against the next rows), which
// the compiler vectorises: several times faster than the same comparisons cell by cell.
BlockBound::BlockBound(const ScoreTable& table, int k)
    : k_(std::max(1, k)), max_(table.width(), table.height()) {
  const int w = table.width(), h = table.height();
  if (w == 0 || h == 0) return;
  ScoreTable rows(w, h);
  for (int j = 0; j < h; ++j) {
    const float* in = table.data() + static_cast<std::ptrdiff_t>(j) * w;
    float* out = rows.data() + static_cast<std::ptrdiff_t>(j) * w;
    std::copy_n(in, w, out);
    for (int d = 1; d < k_ && d < w; ++d) {
      for (int i = 0; i + d < w; ++i) out[i] = std::max(out[i], in[i + d]);
    }
  }
  for (int j = 0; j < h; ++j) {
    float* out = max_.data() + static_cast<std::ptrdiff_t>(j) * w;
    std::copy_n(rows.data() + static_cast<std::ptrdiff_t>(j) * w, w, out);
    for (int d = 1; d < k_ && j + d < h; ++d) {
      const float* in = rows.data() + static_cast<std::ptrdiff_t>(j + d) * w;
      for (int i = 0; i < w; ++i) out[i] = std::max(out[i], in[i]);
    }
  }
}

}  // namespace traverse::correlative
