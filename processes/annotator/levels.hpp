// Accuracy levels of a surveying standard and their colours (seed 004, section 3.2).
//
// A standard is a list of levels, best (smallest 95 % error) first, each ending where the next
// begins; the last is open. The default is the USIBD Level of Accuracy specification (2016), all
// at 95 %: LOA50 0-1 mm, LOA40 1-5 mm, LOA30 5-15 mm, LOA20 15-50 mm, LOA10 over 50 mm. Another
// standard (e.g. the RICS survey bands) is given the same way in the config.
//
// The user picks the best level worth telling apart (green, with every better level) and the
// worst level they accept (red, with every worse level); the levels between take hues from green
// to red through yellow, amber and orange, evenly spaced in hue.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace traverse::annotator {

using Rgb = std::array<uint8_t, 3>;

struct Level {
  std::string name;
  double min_m = 0.0;  // [m] lower end of the 95 % error
  double max_m = 0.0;  // [m] upper end; infinity for the last level
  Rgb rgb{};
  bool accepted = false;  // at or better than the worst accepted level
};

class Legend {
 public:
  Legend() = default;
  // names best first; limits_m the upper ends of all but the last level, increasing [m];
  // best and worst name levels with best at or before worst. The caller validates (validate()).
  Legend(std::string standard, const std::vector<std::string>& names,
         const std::vector<double>& limits_m, const std::string& best, const std::string& worst);

  // The first problem of the constructor's inputs, named by its config key (levels, limits_m,
  // best_level, worst_level); nullopt when they make a legend.
  static std::optional<std::string> validate(const std::vector<std::string>& names,
                                             const std::vector<double>& limits_m,
                                             const std::string& best, const std::string& worst);

  // Index of the level a 95 % bound [m] falls in (a bound on a limit belongs to the better one).
  int level_of(double bound_m) const;
  const std::vector<Level>& levels() const { return levels_; }
  const std::string& standard() const { return standard_; }
  int best() const { return best_; }
  int worst() const { return worst_; }

 private:
  std::string standard_;
  std::vector<Level> levels_;
  int best_ = 0, worst_ = 0;
};

// Colour at t in [0, 1] on the ramp from green (0) to red (1) through yellow and orange.
Rgb ramp_colour(double t);

}  // namespace traverse::annotator
