// The last N values of a stream (a ring): how many are held, and their percentiles.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

namespace traverse::frontend {

template <std::size_t N>
class RecentValues {
 public:
  void add(double value) { values_[count_++ % N] = value; }
  std::size_t size() const { return std::min(count_, N); }
  // The (size() * percent / 100)-th smallest of those held, counting from 0; size() > 0.
  double percentile(std::size_t percent) const {
    std::array<double, N> v = values_;
    const std::size_t n = size(), k = std::min(n - 1, n * percent / 100);
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k),
                     v.begin() + static_cast<std::ptrdiff_t>(n));
    return v[k];
  }

 private:
  std::array<double, N> values_{};
  std::size_t count_ = 0;
};

}  // namespace traverse::frontend
