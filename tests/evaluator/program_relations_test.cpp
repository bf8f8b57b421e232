// The offline program in --relations mode: the estimate scored by relations, the loop closures
// checked by them.
#include "program_harness.hpp"

namespace traverse::evaluator {
namespace {

// --relations on a log: relations between scans 1 s apart, each 2 cm longer in x than the truth
// (relations_test.cpp checks the metric on varied errors; this checks the program: channels,
// counts, keys, CSV, exit codes).
TEST_F(EvaluatorProgram, RelationsModeScoresTheEstimateChannel) {
  const fs::path rel = dir_ / "run.relations";
  {
    std::ofstream out(rel);
    const auto truth = test::circle_truth(10);
    for (std::size_t i = 0; i + 200 < truth.size(); i += 25) {  // frontend scans, 1 s apart
      const Pose2 d = between(truth[i].pose, truth[i + 200].pose);
      out << fmt::format("{}.{:06d} {}.{:06d} {:.9f} {:.9f} 0 0 0 {:.9f}\n",
                         truth[i].utime / 1'000'000, truth[i].utime % 1'000'000,
                         truth[i + 200].utime / 1'000'000, truth[i + 200].utime % 1'000'000,
                         d.x() + 0.02, d.y(), d.theta());
    }
    out << "1.000000 999.000000 0 0 0 0 0 0\n";  // a stamp no scan has: missing
  }
  const RunResult truth = run("--log " + log_ + " --estimate POSE_GROUND_TRUTH --relations " +
                              rel.string() + " --out " + (dir_ / "out").string());
  ASSERT_EQ(truth.exit_code, 0) << truth.last_line;
  EXPECT_EQ(json_value(truth.last_line, "mode"), "relations");
  EXPECT_EQ(json_number(truth.last_line, "relations"), 74);
  EXPECT_EQ(json_number(truth.last_line, "relations_used"), 73);
  EXPECT_EQ(json_number(truth.last_line, "relations_missing"), 1);
  // Every relation 2 cm longer in x than the truth: 0.02 m back, the same for all.
  EXPECT_NEAR(json_number(truth.last_line, "trans_mean_m"), 0.02, 2e-6);
  EXPECT_NEAR(json_number(truth.last_line, "trans_sd_m"), 0.0, 2e-6);
  EXPECT_NEAR(json_number(truth.last_line, "trans_sq_mean_m2"), 4e-4, 1e-7);
  EXPECT_NEAR(json_number(truth.last_line, "rot_mean_deg"), 0.0, 1e-6);
  EXPECT_EQ(json_value(truth.last_line, "estimate_channel"), "POSE_GROUND_TRUTH");
  std::ifstream csv(dir_ / "out" / "relations.csv");
  int rows = -1;
  for (std::string line; std::getline(csv, line);) ++rows;
  EXPECT_EQ(rows, 74);
  // No loop closure on this log: none checked, figures null; the frontend's error over a bridge
  // is still measured by the 73 short relations, each 2 cm off in x: sqrt(0.02^2 / 2) m, with x
  // and y made isotropic.
  EXPECT_EQ(json_number(truth.last_line, "closures"), 0);
  EXPECT_EQ(json_number(truth.last_line, "checked"), 0);
  EXPECT_TRUE(json_value(truth.last_line, "median_sigmas").is_null());
  EXPECT_TRUE(json_value(truth.last_line, "closure_nearer").is_null());
  EXPECT_EQ(json_value(truth.last_line, "frontend_channel"), "POSE_FRONTEND");
  EXPECT_EQ(json_number(truth.last_line, "frontend_poses"), 401);  // every 25th, NaN left out
  EXPECT_NEAR(json_number(truth.last_line, "bridge_sigma_m"), 0.0141, 1e-9);
  EXPECT_NEAR(json_number(truth.last_line, "bridge_sigma_deg"), 0.0, 1e-9);
  EXPECT_TRUE(fs::exists(dir_ / "out" / "closures.csv"));
  // The frontend channel (every 25th truth pose, all 0.3 m off in x: a shift of the whole
  // trajectory, which no relative pose sees): the same relations, the same errors.
  const RunResult frontend = run("--log " + log_ + " --relations " + rel.string());
  EXPECT_EQ(frontend.exit_code, 0) << frontend.last_line;
  EXPECT_EQ(json_number(frontend.last_line, "relations_used"), 73);
  EXPECT_NEAR(json_number(frontend.last_line, "trans_mean_m"), 0.02, 2e-6);
  // A channel with nothing on it: refused, exit 1, figures null.
  const RunResult none =
      run("--log " + log_ + " --estimate POSE_DENSE --relations " + rel.string() + " 2>/dev/null");
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_EQ(json_value(none.last_line, "refused"), true);
  EXPECT_TRUE(json_value(none.last_line, "trans_mean_m").is_null());
}

}  // namespace
}  // namespace traverse::evaluator
