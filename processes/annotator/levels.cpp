#include "levels.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "config.hpp"

namespace traverse::annotator {

Rgb ramp_colour(double t) {
  t = std::clamp(t, 0.0, 1.0);
  // Hue 120 deg (green) to 0 deg (red) at full saturation and value: yellow at 60, amber at 45,
  // orange at 30.
  const double hue = 120.0 * (1.0 - t);
  const double x = 1.0 - std::abs(std::fmod(hue / 60.0, 2.0) - 1.0);
  const double r = hue < 60.0 ? 1.0 : x, g = hue < 60.0 ? x : 1.0;
  return {static_cast<uint8_t>(std::lround(255.0 * r)),
          static_cast<uint8_t>(std::lround(255.0 * g)), 0};
}

std::optional<std::string> Legend::validate(const std::vector<std::string>& names,
                                            const std::vector<double>& limits_m,
                                            const std::string& best, const std::string& worst) {
  ConfigCheck check;
  check.require(names.size() >= 2, "levels", "must name at least two levels");
  check.require(limits_m.size() + 1 == names.size(), "limits_m",
                "must hold one upper limit per level but the last (" +
                    std::to_string(names.empty() ? 0 : names.size() - 1) + "), not " +
                    std::to_string(limits_m.size()));
  for (std::size_t i = 0; i < limits_m.size(); ++i) {
    check.require(limits_m[i] > (i == 0 ? 0.0 : limits_m[i - 1]), "limits_m",
                  "must be positive and increasing");
  }
  const auto b = std::find(names.begin(), names.end(), best);
  const auto w = std::find(names.begin(), names.end(), worst);
  check.require(b != names.end(), "best_level", "'" + best + "' is not one of levels");
  check.require(w != names.end(), "worst_level", "'" + worst + "' is not one of levels");
  check.require(b <= w, "best_level", "must not be worse than worst_level");
  return check.problem();
}

Legend::Legend(std::string standard, const std::vector<std::string>& names,
               const std::vector<double>& limits_m, const std::string& best,
               const std::string& worst)
    : standard_(std::move(standard)) {
  best_ = static_cast<int>(std::find(names.begin(), names.end(), best) - names.begin());
  worst_ = static_cast<int>(std::find(names.begin(), names.end(), worst) - names.begin());
  for (std::size_t i = 0; i < names.size(); ++i) {
    Level l;
    l.name = names[i];
    l.min_m = i == 0 ? 0.0 : limits_m[i - 1];
    l.max_m = i < limits_m.size() ? limits_m[i] : std::numeric_limits<double>::infinity();
    const int span = worst_ - best_;
    const double t = span == 0 ? (static_cast<int>(i) > worst_ ? 1.0 : 0.0)
                               : static_cast<double>(static_cast<int>(i) - best_) / span;
    l.rgb = ramp_colour(t);
    l.accepted = static_cast<int>(i) <= worst_;
    levels_.push_back(l);
  }
}

int Legend::level_of(double bound_m) const {
  for (std::size_t i = 0; i + 1 < levels_.size(); ++i) {
    if (bound_m <= levels_[i].max_m) return static_cast<int>(i);
  }
  return static_cast<int>(levels_.size()) - 1;
}

}  // namespace traverse::annotator
