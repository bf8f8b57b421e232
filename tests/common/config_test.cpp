#include "config.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace traverse {
namespace {

struct GridConfig {
  double resolution_m = 0.05;
  int levels = 3;
  template <class V>
  void visit(V& v) {
    v("resolution_m", resolution_m);
    v("levels", levels);
  }
};

struct NodeConfig {
  std::string frame = "base";
  bool deskew = true;
  std::vector<double> extrinsic = {0, 0, 0};
  GridConfig grid;
  template <class V>
  void visit(V& v) {
    v("frame", frame);
    v("deskew", deskew);
    v("extrinsic", extrinsic);
    v("grid", grid);
  }
};

std::string error_of(const std::string& yaml) {
  NodeConfig c;
  try {
    load_config_text(yaml, "test.yaml", c);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Config, DefaultsStayForAbsentKeys) {
  NodeConfig c;
  load_config_text("grid:\n  levels: 4\n", "test.yaml", c);
  EXPECT_EQ(c.grid.levels, 4);
  EXPECT_DOUBLE_EQ(c.grid.resolution_m, 0.05);
  EXPECT_EQ(c.frame, "base");
  EXPECT_TRUE(c.deskew);
}

TEST(Config, ReadsAllKinds) {
  NodeConfig c;
  load_config_text("frame: laser\ndeskew: false\nextrinsic: [1, 2.5, -3]\n", "t.yaml", c);
  EXPECT_EQ(c.frame, "laser");
  EXPECT_FALSE(c.deskew);
  ASSERT_EQ(c.extrinsic.size(), 3u);
  EXPECT_DOUBLE_EQ(c.extrinsic[1], 2.5);
}

TEST(Config, EmptyFileKeepsDefaults) {
  NodeConfig c;
  load_config_text("", "t.yaml", c);
  EXPECT_EQ(c.grid.levels, 3);
}

TEST(Config, UnknownKeyNamesKeyAndFile) {
  EXPECT_EQ(error_of("framee: x\n"), "test.yaml: unknown key 'framee'");
  EXPECT_EQ(error_of("grid:\n  resolution: 0.1\n"), "test.yaml: unknown key 'grid.resolution'");
}

TEST(Config, ARepeatedKeyNamesKeyAndFile) {
  // YAML parsers keep the first of two equal keys: the second was ignored without a word.
  EXPECT_EQ(error_of("frame: a\ndeskew: true\nframe: b\n"), "test.yaml: key 'frame' appears twice");
  EXPECT_EQ(error_of("grid:\n  levels: 2\n  levels: 5\n"),
            "test.yaml: key 'grid.levels' appears twice");
}

TEST(Config, AMappingAsKeyIsAnErrorNotACrash) { EXPECT_NE(error_of("? [a, b]\n: 1\n"), ""); }

TEST(Config, MistypedValueNamesKey) {
  EXPECT_EQ(error_of("grid:\n  levels: many\n"),
            "test.yaml: key 'grid.levels' expects an integer, got 'many'");
  EXPECT_EQ(error_of("grid:\n  levels: 2.5\n"),
            "test.yaml: key 'grid.levels' expects an integer, got '2.5'");
  EXPECT_EQ(error_of("deskew: maybe\n"),
            "test.yaml: key 'deskew' expects true or false, got 'maybe'");
  EXPECT_EQ(error_of("grid: 3\n"), "test.yaml: key 'grid' expects a mapping of keys, got '3'");
  EXPECT_EQ(error_of("extrinsic: [1, a]\n"),
            "test.yaml: key 'extrinsic[1]' expects a finite number, got 'a'");
}

TEST(Config, TopLevelMustBeMapping) {
  EXPECT_NE(error_of("- 1\n- 2\n").find("top level must be a mapping"), std::string::npos);
}

TEST(Config, MissingFileNamesPath) {
  NodeConfig c;
  try {
    load_config("/nonexistent/dir/x.yaml", c);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/x.yaml"), std::string::npos);
  }
}

TEST(Config, BadYamlNamesFile) {
  const auto path = std::filesystem::temp_directory_path() / "traverse_config_test_bad.yaml";
  std::ofstream(path) << "grid: [1, 2\n";
  NodeConfig c;
  try {
    load_config(path.string(), c);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string() + ": not valid YAML"), std::string::npos);
  }
  std::filesystem::remove(path);
}

TEST(Config, NonFiniteNumbersAreRefusedNamingKeyAndFile) {
  for (const char* v : {".inf", "-.inf", ".nan", ".Inf", ".NaN"}) {
    const std::string e = error_of(std::string("grid:\n  resolution_m: ") + v + "\n");
    EXPECT_NE(e.find("test.yaml"), std::string::npos) << v;
    EXPECT_NE(e.find("grid.resolution_m"), std::string::npos) << v;
    EXPECT_NE(e.find("finite"), std::string::npos) << v;
  }
  const std::string list = error_of("extrinsic: [0, .nan, 0]\n");
  EXPECT_NE(list.find("extrinsic[1]"), std::string::npos) << list;
}

std::optional<std::string> validate(const GridConfig& c) {
  ConfigCheck check;
  check.positive("resolution_m", c.resolution_m);
  check.in_range("levels", c.levels, 1, 8);
  return check.problem();
}

std::optional<std::string> validate(const NodeConfig& c) {
  ConfigCheck check;
  check.not_empty("frame", c.frame);
  check.nested("grid", validate(c.grid));
  check.require(c.extrinsic.size() == 3, "extrinsic", "must hold x, y, z");
  return check.problem();
}

TEST(ConfigCheck, NamesTheFirstBadKeyWithItsPath) {
  NodeConfig c;
  EXPECT_FALSE(validate(c).has_value());
  c.grid.resolution_m = 0.0;
  c.grid.levels = 9;
  ASSERT_TRUE(validate(c).has_value());
  EXPECT_EQ(*validate(c), "key 'grid.resolution_m' must be positive, got 0");
  c.grid.resolution_m = 0.1;
  EXPECT_EQ(*validate(c), "key 'grid.levels' must be in [1, 8], got 9");
  c.grid.levels = 2;
  c.frame.clear();
  EXPECT_EQ(*validate(c), "key 'frame' must not be empty");
}

}  // namespace
}  // namespace traverse
