#include "json.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace traverse {
namespace {

Json printed(std::optional<double> v, const char* format, int precision) {
  if (!v || !std::isfinite(*v)) return nullptr;
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, precision, *v);
  return std::strtod(buf, nullptr);
}

}  // namespace

Json json_fixed(std::optional<double> v, int decimals) { return printed(v, "%.*f", decimals); }

Json json_significant(std::optional<double> v, int digits) { return printed(v, "%.*g", digits); }

std::string json_line(const Json& j) {
  return j.dump(-1, ' ', true, Json::error_handler_t::replace);
}

}  // namespace traverse
