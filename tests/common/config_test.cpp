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

TEST(Config, MistypedValueNamesKey) {
  EXPECT_EQ(error_of("grid:\n  levels: many\n"),
            "test.yaml: key 'grid.levels' expects an integer, got 'many'");
  EXPECT_EQ(error_of("grid:\n  levels: 2.5\n"),
            "test.yaml: key 'grid.levels' expects an integer, got '2.5'");
  EXPECT_EQ(error_of("deskew: maybe\n"), "test.yaml: key 'deskew' expects true or false, got 'maybe'");
  EXPECT_EQ(error_of("grid: 3\n"), "test.yaml: key 'grid' expects a mapping of keys, got '3'");
  EXPECT_EQ(error_of("extrinsic: [1, a]\n"),
            "test.yaml: key 'extrinsic[1]' expects a number, got 'a'");
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

}  // namespace
}  // namespace traverse
