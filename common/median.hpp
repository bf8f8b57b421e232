// The median of a sample: the middle value, or the mean of the middle two for an even count.
#pragma once

#include <algorithm>
#include <optional>
#include <vector>

namespace traverse {

// nullopt for an empty sample.
inline std::optional<double> median(std::vector<double> values) {
  if (values.empty()) return std::nullopt;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  if (values.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(values.begin(), mid));
}

}  // namespace traverse
