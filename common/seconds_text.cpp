#include "seconds_text.hpp"

#include <string>

namespace traverse {

std::optional<int64_t> seconds_text_to_utime(std::string_view s) {
  std::size_t i = 0;
  bool negative = false;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) negative = s[i++] == '-';
  // All mantissa digits, and how many stand before the point.
  std::string digits;
  long point = -1;
  for (; i < s.size(); ++i) {
    if (s[i] == '.' && point < 0) {
      point = static_cast<long>(digits.size());
    } else if (s[i] >= '0' && s[i] <= '9') {
      if (digits.size() < 64) digits.push_back(s[i]);  // beyond 64 digits: below a microsecond
    } else {
      break;
    }
  }
  if (digits.empty()) return std::nullopt;
  if (point < 0) point = static_cast<long>(digits.size());
  long exponent = 0;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    bool exp_negative = false;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) exp_negative = s[i++] == '-';
    const std::size_t start = i;
    for (; i < s.size() && s[i] >= '0' && s[i] <= '9'; ++i) {
      if (exponent < 1000) exponent = exponent * 10 + (s[i] - '0');
    }
    if (i == start) return std::nullopt;
    if (exp_negative) exponent = -exponent;
  }
  if (i != s.size()) return std::nullopt;
  // The microseconds are the digits up to 6 places after the (shifted) point; the next digit
  // decides the rounding (halves away from zero), exactly.
  const long end = point + exponent + 6;
  const auto digit = [&](long k) {
    return k >= 0 && k < static_cast<long>(digits.size())
               ? digits[static_cast<std::size_t>(k)] - '0'
               : 0;
  };
  constexpr int64_t kMaxUtime = static_cast<int64_t>(kMaxSecondsText * 1e6);
  int64_t v = 0;
  for (long k = 0; k < end; ++k) {
    if (v > kMaxUtime / 10) return std::nullopt;
    v = v * 10 + digit(k);
  }
  if (digit(end) >= 5) ++v;
  if (v > kMaxUtime) return std::nullopt;
  return negative ? -v : v;
}

}  // namespace traverse
