// The legend: USIBD LOA levels, the colour ramp between the user's best and worst level, checks.
#include "levels.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace traverse::annotator {
namespace {

const std::vector<std::string> kNames{"LOA50", "LOA40", "LOA30", "LOA20", "LOA10"};
const std::vector<double> kLimits{0.001, 0.005, 0.015, 0.050};

TEST(Legend, BoundsFallIntoTheirLevels) {
  const Legend legend("USIBD LOA", kNames, kLimits, "LOA40", "LOA20");
  EXPECT_EQ(legend.level_of(0.0), 0);
  EXPECT_EQ(legend.level_of(0.001), 0);  // a limit belongs to the better level
  EXPECT_EQ(legend.level_of(0.0011), 1);
  EXPECT_EQ(legend.level_of(0.014), 2);
  EXPECT_EQ(legend.level_of(0.03), 3);
  EXPECT_EQ(legend.level_of(7.0), 4);
  EXPECT_EQ(legend.levels()[4].min_m, 0.050);
  EXPECT_TRUE(std::isinf(legend.levels()[4].max_m));
}

TEST(Legend, GreenAtTheBestRedAtTheWorstHuesBetween) {
  const Legend legend("USIBD LOA", kNames, kLimits, "LOA40", "LOA20");
  const Rgb green{0, 255, 0}, red{255, 0, 0};
  EXPECT_EQ(legend.levels()[0].rgb, green);  // better than the best: green too
  EXPECT_EQ(legend.levels()[1].rgb, green);
  EXPECT_EQ(legend.levels()[2].rgb, (Rgb{255, 255, 0}));  // halfway: yellow
  EXPECT_EQ(legend.levels()[3].rgb, red);
  EXPECT_EQ(legend.levels()[4].rgb, red);  // worse than the worst accepted: red too
  EXPECT_TRUE(legend.levels()[3].accepted);
  EXPECT_FALSE(legend.levels()[4].accepted);
  // Orange lies between yellow and red: red full, green falling.
  const Rgb orange = ramp_colour(0.75);
  EXPECT_EQ(orange[0], 255);
  EXPECT_GT(orange[1], 0);
  EXPECT_LT(orange[1], 255);
}

TEST(Legend, ValidationNamesTheProblem) {
  EXPECT_FALSE(Legend::validate(kNames, kLimits, "LOA30", "LOA10"));
  EXPECT_NE(
      Legend::validate(kNames, {0.001, 0.005}, "LOA30", "LOA10").value_or("").find("limits_m"),
      std::string::npos);
  EXPECT_NE(Legend::validate(kNames, {0.001, 0.005, 0.004, 0.05}, "LOA30", "LOA10")
                .value_or("")
                .find("increasing"),
            std::string::npos);
  EXPECT_NE(Legend::validate(kNames, kLimits, "LOA31", "LOA10").value_or("").find("best_level"),
            std::string::npos);
  EXPECT_NE(Legend::validate(kNames, kLimits, "LOA10", "LOA30").value_or("").find("worse"),
            std::string::npos);
}

}  // namespace
}  // namespace traverse::annotator
