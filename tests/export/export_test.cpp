// traverse-export's pieces: the LAS 1.4 writer read back by an independent reader
// (tests/export/read_las.py, written from the specification), the trajectory's covariances,
// levels and colours, the TUM lines, and the cloud export with thinning and a frame change.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "export_cloud.hpp"
#include "las_writer.hpp"
#include "products.hpp"

namespace fs = std::filesystem;
namespace ex = traverse::exporter;

namespace {

fs::path temp_dir(const std::string& name) {
  fs::path d = fs::temp_directory_path() /
               ("traverse-export-test-" + name + "-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

nlohmann::json read_las(const fs::path& path) {
  const std::string cmd = "python3 tests/export/read_las.py " + path.string();
  std::FILE* p = ::popen(cmd.c_str(), "r");
  std::string out;
  char buf[65536];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
  EXPECT_EQ(::pclose(p), 0) << out;
  return nlohmann::json::parse(out);
}

}  // namespace

TEST(LasWriter, IndependentReaderReadsEveryField) {
  const fs::path dir = temp_dir("las");
  const fs::path file = dir / "a.las";
  {
    traverse::LasWriter w(file.string(), ex::local_frame_wkt("world"),
                          {{"loa_level", traverse::LasExtraField::Type::kU8, "level"},
                           {"bound95_m", traverse::LasExtraField::Type::kF32, "bound"}},
                          "traverse-test");
    ASSERT_TRUE(w.good()) << w.error();
    EXPECT_TRUE(w.add({46.2, 15.2, 1.25, 1000, 1700000000.5, 0, 51400, 0, 0, {40, 0.0042}}));
    EXPECT_TRUE(w.add({-3.0001, 2.5, 0.0, 65535, 1700000001.25, 56540, 0, 0, 0, {10, 0.25}}));
    EXPECT_FALSE(w.add({0, 0, 0, 0, 0, 0, 0, 0, 0, {1}}));  // wrong number of extra values
    EXPECT_FALSE(w.close());
  }
  {
    traverse::LasWriter w(file.string(), ex::local_frame_wkt("world"),
                          {{"loa_level", traverse::LasExtraField::Type::kU8, "level"},
                           {"bound95_m", traverse::LasExtraField::Type::kF32, "bound"}},
                          "traverse-test");
    EXPECT_TRUE(w.add({46.2, 15.2, 1.25, 1000, 1700000000.5, 0, 51400, 0, 0, {40, 0.0042}}));
    EXPECT_TRUE(w.add({-3.0001, 2.5, 0.0, 65535, 1700000001.25, 56540, 0, 0, 0, {10, 0.25}}));
    ASSERT_TRUE(w.close()) << w.error();
  }
  const nlohmann::json j = read_las(file);
  const auto& h = j["header"];
  EXPECT_EQ(h["version"], "1.4");
  EXPECT_EQ(h["point_format"], 7);
  EXPECT_EQ(h["points"], 2);
  EXPECT_EQ(h["legacy_points"], 0);
  EXPECT_EQ(h["global_encoding"].get<int>() & 17, 17);  // adjusted GPS time, WKT
  EXPECT_EQ(h["header_size"], 375);
  EXPECT_NEAR(h["min"][0].get<double>(), -3.0001, 1e-9);
  EXPECT_NEAR(h["max"][1].get<double>(), 15.2, 1e-9);
  EXPECT_NE(j["wkt"].get<std::string>().find("traverse world"), std::string::npos);
  ASSERT_EQ(j["extra_fields"].size(), 2u);
  EXPECT_EQ(j["extra_fields"][0]["name"], "loa_level");
  EXPECT_EQ(j["extra_fields"][1]["name"], "bound95_m");
  const auto& p = j["points"];
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NEAR(p[0]["x"].get<double>(), 46.2, 1e-4);
  EXPECT_NEAR(p[0]["y"].get<double>(), 15.2, 1e-4);
  EXPECT_NEAR(p[0]["z"].get<double>(), 1.25, 1e-4);
  EXPECT_NEAR(p[1]["x"].get<double>(), -3.0001, 1e-4);
  EXPECT_EQ(p[0]["intensity"], 1000);
  EXPECT_EQ(p[1]["intensity"], 65535);
  EXPECT_EQ(p[0]["return_byte"], 0x11);
  // 1700000000.5 Unix = 2023-11-14T22:13:20.5Z; GPS is 18 s ahead of UTC; adjusted = GPS - 1e9.
  EXPECT_NEAR(p[0]["gps_time"].get<double>(), 1700000000.5 - 315964800 + 18 - 1e9, 1e-6);
  EXPECT_EQ(p[0]["rgb"], nlohmann::json({0, 51400, 0}));
  EXPECT_EQ(p[1]["rgb"], nlohmann::json({56540, 0, 0}));
  EXPECT_EQ(p[0]["extra"]["loa_level"], 40);
  EXPECT_NEAR(p[1]["extra"]["bound95_m"].get<double>(), 0.25, 1e-7);
  fs::remove_all(dir);
}

TEST(Products, LevelsColoursAndBounds) {
  EXPECT_EQ(ex::loa_level(0.0), 50);
  EXPECT_EQ(ex::loa_level(0.003), 40);
  EXPECT_EQ(ex::loa_level(0.010), 30);
  EXPECT_EQ(ex::loa_level(0.040), 20);
  EXPECT_EQ(ex::loa_level(0.2), 10);
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  c(0, 0) = 0.0001;  // 1 cm SD in x, 0.5 cm in y
  c(1, 1) = 0.000025;
  EXPECT_NEAR(ex::bound95_m(c), 0.02, 1e-12);
  const auto green = ex::level_colour(50, 40, 20), top = ex::level_colour(40, 40, 20);
  const auto mid = ex::level_colour(30, 40, 20), bottom = ex::level_colour(20, 40, 20);
  const auto red = ex::level_colour(10, 40, 20);
  EXPECT_EQ(green, top);
  EXPECT_EQ(top[0], 0);
  EXPECT_EQ(red[1], 0);
  EXPECT_GT(mid[1], bottom[1]);  // yellow, then orange
  EXPECT_NE(mid, red);
}

TEST(Products, DenseCovarianceInterpolatesKeyPosesAndRotatesWithTheFrame) {
  ex::RunEstimate run;
  Eigen::Matrix3d c1 = Eigen::Matrix3d::Zero();
  c1(0, 0) = 4e-4;
  c1(1, 1) = 1e-4;
  run.key_poses[0] = {1'000'000, traverse::Pose2(0, 0, 0), Eigen::Matrix3d::Zero()};
  run.key_poses[1] = {3'000'000, traverse::Pose2(2, 0, 0), c1};
  run.segments[0] = {
      0,
      1,
      0,
      {1'000'000, 2'000'000, 3'000'000},
      {traverse::Pose2(0, 0, 0), traverse::Pose2(1, 0, 0), traverse::Pose2(2, 0, 0)}};
  run.segments[1] = {
      1, 2, 0, {3'000'000, 4'000'000}, {traverse::Pose2(2, 0, 0), traverse::Pose2(3, 0, 0)}};
  const auto dense = ex::dense_trajectory(run);
  ASSERT_EQ(dense.size(), 4u);  // the shared end pose once
  EXPECT_NEAR(dense[1].covariance(0, 0), 2e-4, 1e-15);
  EXPECT_NEAR(dense[2].covariance(0, 0), 4e-4, 1e-15);
  // Ground truth: the map frame's origin sits at (10, 5) facing +y in the world.
  run.ground_truth = {{0, traverse::Pose2(10, 5, M_PI / 2)},
                      {2'000'000, traverse::Pose2(10, 7, M_PI / 2)}};
  const auto T = ex::world_from_map(run, dense);
  ASSERT_TRUE(T);
  const ex::DensePose w = ex::transformed(dense[2], *T);
  EXPECT_NEAR(w.pose.x(), 10.0, 1e-9);
  EXPECT_NEAR(w.pose.y(), 8.0, 1e-9);
  EXPECT_NEAR(w.covariance(1, 1), 4e-4, 1e-12);  // x's variance is now along y
  EXPECT_NEAR(w.covariance(0, 0), 1e-4, 1e-12);
}

TEST(Products, TumLinesAreTimePositionQuaternion) {
  const fs::path dir = temp_dir("tum");
  ex::DensePose p;
  p.utime = 1'700'000'000'250'000;
  p.pose = traverse::Pose2(1.5, -2.0, M_PI / 2);
  ASSERT_TRUE(ex::write_tum((dir / "t.tum").string(), {p}, "map"));
  std::ifstream f(dir / "t.tum");
  std::string comment, line;
  std::getline(f, comment);
  std::getline(f, line);
  EXPECT_EQ(comment[0], '#');
  EXPECT_NE(comment.find("frame map"), std::string::npos);
  double t, x, y, z, qx, qy, qz, qw;
  std::istringstream(line) >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
  EXPECT_NEAR(t, 1700000000.25, 1e-6);
  EXPECT_NEAR(x, 1.5, 1e-6);
  EXPECT_NEAR(qz, std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(qw, std::sqrt(0.5), 1e-9);
  fs::remove_all(dir);
}

TEST(ExportCloud, ThinsMovesIntoTheFrameAndColoursByLevel) {
  const fs::path dir = temp_dir("cloud");
  // A cloud in the mapper's layout: x y z float, intensity uchar, time double, key_id int.
  {
    std::ofstream f(dir / "in.ply", std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty float x\n"
         "property float y\nproperty float z\nproperty uchar intensity\nproperty double time\n"
         "property int key_id\nend_header\n";
    for (int i = 0; i < 10; ++i) {
      const float xyz[3] = {static_cast<float>(i), 0.0f, 1.0f};
      const uint8_t in = static_cast<uint8_t>(10 * i);
      const double t = 1700000001.0 + 0.1 * i;
      const int32_t k = 0;
      f.write(reinterpret_cast<const char*>(xyz), 12);
      f.write(reinterpret_cast<const char*>(&in), 1);
      f.write(reinterpret_cast<const char*>(&t), 8);
      f.write(reinterpret_cast<const char*>(&k), 4);
    }
  }
  ex::RunEstimate run;
  Eigen::Matrix3d c1 = Eigen::Matrix3d::Zero();
  c1(0, 0) = c1(1, 1) = 0.05 * 0.05;  // 95 % bound 0.1 m: LOA 10 at the segment's end
  run.key_poses[0] = {1'700'000'001'000'000, traverse::Pose2(), Eigen::Matrix3d::Zero()};
  run.key_poses[1] = {1'700'000'002'000'000, traverse::Pose2(), c1};
  run.segments[0] = {0,
                     1,
                     0,
                     {1'700'000'001'000'000, 1'700'000'002'000'000},
                     {traverse::Pose2(), traverse::Pose2()}};
  ex::CloudOptions o;
  o.las_path = (dir / "out.las").string();
  o.ply_path = (dir / "out.ply").string();
  o.frame = "world";
  o.T_out_map = traverse::Pose2(100, 0, M_PI);
  o.thin_every = 3;
  ex::CloudSummary s;
  std::string error;
  ASSERT_TRUE(ex::export_cloud((dir / "in.ply").string(), run, o, &s, &error)) << error;
  EXPECT_EQ(s.read, 10);
  EXPECT_EQ(s.written, 4);  // points 0, 3, 6, 9
  const nlohmann::json j = read_las(dir / "out.las");
  ASSERT_EQ(j["points"].size(), 4u);
  EXPECT_NEAR(j["points"][1]["x"].get<double>(), 97.0, 1e-4);  // (3, 0) turned by pi, +100
  EXPECT_NEAR(j["points"][1]["z"].get<double>(), 1.0, 1e-4);
  EXPECT_EQ(j["points"][1]["intensity"], 30 * 257);
  EXPECT_EQ(j["points"][0]["extra"]["loa_level"], 50);  // at the exact key pose
  EXPECT_EQ(j["points"][3]["extra"]["loa_level"], 10);  // 0.09 m bound
  EXPECT_EQ(j["points"][3]["rgb"][1], 0);               // red
  EXPECT_NE(j["wkt"].get<std::string>().find("traverse world"), std::string::npos);
  // The PLY holds the same points, readable by the same reader that reads the mapper's.
  int64_t n = ex::read_ply_points((dir / "out.ply").string(), [](const ex::CloudPoint&) {}, &error);
  EXPECT_EQ(n, 4) << error;
  fs::remove_all(dir);
}
