#include "correlative_search.hpp"

namespace traverse::correlative {

BlockBound::BlockBound(const ScoreTable& table, int k)
    : k_(std::max(1, k)), max_(table.width(), table.height()) {
  // Separably: the largest of k cells towards +i, then of k of those towards +j.
  const int w = table.width(), h = table.height();
  ScoreTable rows(w, h);
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      float m = table.at(i, j);
      for (int d = 1; d < k_ && i + d < w; ++d) m = std::max(m, table.at(i + d, j));
      rows.at(i, j) = m;
    }
  }
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      float m = rows.at(i, j);
      for (int d = 1; d < k_ && j + d < h; ++d) m = std::max(m, rows.at(i, j + d));
      max_.at(i, j) = m;
    }
  }
}

}  // namespace traverse::correlative
