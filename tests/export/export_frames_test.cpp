// traverse-export end to end on a run written here, where the truth is known: the estimate is
// exact, the map frame sits at a chosen pose in the simulator's world and the first dense pose is
// not at the map's origin (a frontend's initial_pose). With --frame world every product must then
// lie on the ground truth; with --frame map the ground truth must be moved onto the estimate; and
// every file must say which frame it is in (TUM comment, CSV column, PLY comment, LAS WKT, JSON).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "export_cloud.hpp"
#include "publisher.hpp"
#include "run_program.hpp"
#include "se2.hpp"
#include "traverse/dense_segments_t.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace fs = std::filesystem;
namespace ex = traverse::exporter;
using traverse::Pose2;

namespace {

const std::string kExport = std::string(TRAVERSE_BIN_DIR) + "/traverse-export";
const Pose2 kWorldFromMap(10.0, 5.0, M_PI / 2);  // T_world_map of the run
constexpr int kPoses = 21;                       // dense poses, key poses at 0, 10, 20
constexpr int64_t kT0 = 1'700'000'000'000'000;   // [us]

int64_t utime(int i) { return kT0 + 100'000 * i; }
// T_map_base of dense pose i: starts away from the map's origin, then curves.
Pose2 map_pose(int i) { return Pose2(1.0 + 0.5 * i, -0.3 + 0.02 * i * i, 0.2 + 0.05 * i); }
// A cloud point of dense pose i in the map frame (as the mapper writes it).
Eigen::Vector3d map_point(int i) { return {2.0 + i, 0.5 * i, 1.25}; }

struct TumPose {
  double t, x, y, theta;
};

struct Files {
  std::string tum_comment;
  std::vector<TumPose> trajectory, ground_truth;
  std::vector<std::string> csv_frames;
  std::string ply_header;
  nlohmann::json las, summary;
};

std::vector<TumPose> read_tum(const fs::path& path, std::string* comment) {
  std::ifstream f(path);
  std::vector<TumPose> out;
  std::string line;
  while (std::getline(f, line)) {
    if (line.empty()) continue;
    if (line[0] == '#') {
      if (comment) *comment = line;
      continue;
    }
    double t, x, y, z, qx, qy, qz, qw;
    std::istringstream(line) >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
    out.push_back({t, x, y, 2.0 * std::atan2(qz, qw)});
  }
  return out;
}

class ExportFrames : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("traverse-export-frames-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    write_run();
    write_cloud();
  }
  void TearDown() override { fs::remove_all(dir_); }

  void write_run() {
    traverse::LogFilePublisher log((dir_ / "run.lcmlog").string());
    for (int i = 0; i < kPoses; ++i) {
      traverse::pose2d_t gt{};
      gt.utime = utime(i);
      gt.seq = i;
      gt.parent_frame = "world";
      gt.child_frame = "base";
      const Pose2 T_world_base = kWorldFromMap * map_pose(i);
      gt.x = T_world_base.x();
      gt.y = T_world_base.y();
      gt.theta = T_world_base.theta();
      log.publish("POSE_GROUND_TRUTH", gt);
    }
    traverse::key_poses_t keys{};
    keys.utime = utime(kPoses - 1);
    keys.optimisation = 1;
    keys.parts = 1;
    for (int i = 0; i < kPoses; i += 10) {
      traverse::key_pose_t k{};
      k.utime = utime(i);
      k.id = i / 10;
      k.x = map_pose(i).x();
      k.y = map_pose(i).y();
      k.theta = map_pose(i).theta();
      k.covariance[0] = k.covariance[4] = 1e-6 * i * i;  // grows along the run
      k.covariance[8] = 1e-8;
      keys.poses.push_back(k);
    }
    keys.n_poses = static_cast<int32_t>(keys.poses.size());
    keys.total_key_poses = keys.n_poses;
    log.publish("KEY_POSES", keys);
    traverse::dense_segments_t segments{};
    segments.utime = utime(kPoses - 1);
    segments.parent_frame = "map";
    segments.child_frame = "base";
    segments.optimisation = 1;
    segments.parts = 1;
    for (int first = 0; first + 10 < kPoses; first += 10) {
      traverse::dense_segment_t s{};
      s.key_id_first = first / 10;
      s.key_id_last = first / 10 + 1;
      for (int i = first; i <= first + 10; ++i) {
        s.pose_utime.push_back(utime(i));
        s.x.push_back(map_pose(i).x());
        s.y.push_back(map_pose(i).y());
        s.theta.push_back(map_pose(i).theta());
      }
      s.n_poses = static_cast<int32_t>(s.x.size());
      segments.segments.push_back(s);
    }
    segments.n_segments = static_cast<int32_t>(segments.segments.size());
    log.publish("DENSE_SEGMENTS", segments);
  }

  // The mapper's layout: x y z float, intensity uchar, time double, key_id int.
  void write_cloud() {
    std::ofstream f(dir_ / "mapper.ply", std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\nelement vertex " << kPoses
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar intensity\n"
         "property double time\nproperty int key_id\nend_header\n";
    for (int i = 0; i < kPoses; ++i) {
      const Eigen::Vector3d p = map_point(i);
      const float xyz[3] = {static_cast<float>(p.x()), static_cast<float>(p.y()),
                            static_cast<float>(p.z())};
      const uint8_t intensity = 100;
      const double t = 1e-6 * static_cast<double>(utime(i));
      const int32_t key = std::min(i / 10, 1);
      f.write(reinterpret_cast<const char*>(xyz), 12);
      f.write(reinterpret_cast<const char*>(&intensity), 1);
      f.write(reinterpret_cast<const char*>(&t), 8);
      f.write(reinterpret_cast<const char*>(&key), 4);
    }
  }

  Files export_in(const std::string& frame) {
    const fs::path out = dir_ / frame;
    const auto r = traverse::test::run_program(
        kExport + " --log " + (dir_ / "run.lcmlog").string() + " --cloud " +
        (dir_ / "mapper.ply").string() + " --out " + out.string() + " --frame " + frame);
    EXPECT_EQ(r.exit_code, 0) << r.out;
    Files f;
    f.summary = nlohmann::json::parse(r.last_line());
    f.trajectory = read_tum(out / "trajectory.tum", &f.tum_comment);
    f.ground_truth = read_tum(out / "ground_truth.tum", nullptr);
    std::ifstream csv(out / "trajectory.csv");
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line.substr(0, 31), "time_s,x_m,y_m,theta_rad,frame,");
    while (std::getline(csv, line)) {
      std::vector<std::string> cells;
      std::stringstream s(line);
      for (std::string c; std::getline(s, c, ',');) cells.push_back(c);
      f.csv_frames.push_back(cells.at(4));
    }
    std::ifstream ply(out / "cloud.ply", std::ios::binary);
    while (std::getline(ply, line) && line != "end_header") f.ply_header += line + "\n";
    f.las = read_las(out / "cloud.las");
    return f;
  }

  static nlohmann::json read_las(const fs::path& path) {
    const auto r = traverse::test::run_program("python3 tests/export/read_las.py " + path.string());
    EXPECT_EQ(r.exit_code, 0);
    return nlohmann::json::parse(r.out);
  }

  fs::path dir_;
};

void expect_same(const std::vector<TumPose>& a, const std::vector<TumPose>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a[i].t, b[i].t, 1e-6);
    EXPECT_NEAR(a[i].x, b[i].x, 2e-6) << "pose " << i;
    EXPECT_NEAR(a[i].y, b[i].y, 2e-6) << "pose " << i;
    EXPECT_NEAR(std::remainder(a[i].theta - b[i].theta, 2 * M_PI), 0.0, 1e-7) << "pose " << i;
  }
}

TEST_F(ExportFrames, WorldPutsEveryProductOnTheGroundTruth) {
  const Files f = export_in("world");
  EXPECT_EQ(f.summary["frame"], "world");
  EXPECT_NEAR(f.summary["T_world_map"]["x_m"].get<double>(), kWorldFromMap.x(), 1e-9);
  EXPECT_NEAR(f.summary["T_world_map"]["y_m"].get<double>(), kWorldFromMap.y(), 1e-9);
  EXPECT_NEAR(f.summary["T_world_map"]["theta_rad"].get<double>(), kWorldFromMap.theta(), 1e-9);
  EXPECT_NE(f.tum_comment.find("T_world_base, frame world"), std::string::npos) << f.tum_comment;
  ASSERT_EQ(f.trajectory.size(), static_cast<std::size_t>(kPoses));
  for (int i = 0; i < kPoses; ++i) {
    const Pose2 T_world_base = kWorldFromMap * map_pose(i);
    EXPECT_NEAR(f.trajectory[i].x, T_world_base.x(), 2e-6) << "pose " << i;
    EXPECT_NEAR(f.trajectory[i].y, T_world_base.y(), 2e-6) << "pose " << i;
  }
  expect_same(f.trajectory, f.ground_truth);  // the ground truth as the simulator gave it
  for (const auto& frame : f.csv_frames) EXPECT_EQ(frame, "world");
  EXPECT_NE(f.ply_header.find("in frame world"), std::string::npos) << f.ply_header;
  EXPECT_NE(f.las["wkt"].get<std::string>().find("traverse world"), std::string::npos);
  ASSERT_EQ(f.las["points"].size(), static_cast<std::size_t>(kPoses));
  for (int i = 0; i < kPoses; ++i) {
    const Eigen::Vector2d w = kWorldFromMap * Eigen::Vector2d(map_point(i).head<2>());
    const auto& p = f.las["points"][i];
    EXPECT_NEAR(p["x"].get<double>(), w.x(), 2e-4) << "point " << i;  // 0.1 mm LAS steps,
    EXPECT_NEAR(p["y"].get<double>(), w.y(), 2e-4) << "point " << i;  // float PLY input
    EXPECT_NEAR(p["z"].get<double>(), map_point(i).z(), 2e-4) << "point " << i;
  }
}

TEST_F(ExportFrames, MapKeepsTheEstimateAndMovesTheGroundTruthOntoIt) {
  const Files f = export_in("map");
  EXPECT_EQ(f.summary["frame"], "map");
  EXPECT_NE(f.tum_comment.find("T_map_base, frame map"), std::string::npos) << f.tum_comment;
  ASSERT_EQ(f.trajectory.size(), static_cast<std::size_t>(kPoses));
  for (int i = 0; i < kPoses; ++i) {
    EXPECT_NEAR(f.trajectory[i].x, map_pose(i).x(), 2e-6) << "pose " << i;
    EXPECT_NEAR(f.trajectory[i].y, map_pose(i).y(), 2e-6) << "pose " << i;
  }
  expect_same(f.trajectory, f.ground_truth);
  for (const auto& frame : f.csv_frames) EXPECT_EQ(frame, "map");
  EXPECT_NE(f.ply_header.find("in frame map"), std::string::npos) << f.ply_header;
  EXPECT_NE(f.las["wkt"].get<std::string>().find("traverse map"), std::string::npos);
  ASSERT_EQ(f.las["points"].size(), static_cast<std::size_t>(kPoses));
  EXPECT_NEAR(f.las["points"][3]["x"].get<double>(), map_point(3).x(), 2e-4);
  EXPECT_NEAR(f.las["points"][3]["y"].get<double>(), map_point(3).y(), 2e-4);
}

TEST_F(ExportFrames, WorldWithoutGroundTruthIsRefused) {
  const auto r = traverse::test::run_program(kExport + " --log " + (dir_ / "run.lcmlog").string() +
                                             " --out " + (dir_ / "none").string() +
                                             " --frame world --reference POSE_REFERENCE");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "none" / "trajectory.tum"));
}

}  // namespace
