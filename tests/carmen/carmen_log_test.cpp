// The CARMEN reader on hand-made lines: it parses what is right and never trusts what is not
// (truncated lines, non-numbers, NaN, absurd beam counts, binary junk, damaged gzip).
#include "carmen_log.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>

#include "log_reader.hpp"

namespace traverse::carmen {
namespace {

constexpr double kPi = std::numbers::pi;

std::string flaser_line(int n, const std::string& ts = "12.5") {
  std::ostringstream s;
  s << "FLASER " << n;
  for (int i = 0; i < n; ++i) s << ' ' << 1.0 + 0.01 * i;
  s << " 1.5 -2.25 0.75 0 0 0 " << ts << " pippo " << ts;
  return s.str();
}

const std::string kRobotLaser =
    "ROBOTLASER1 0 -1.5708 3.14159 0.0174533 81.9 0.01 0 3 1.0 2.0 3.0 2 10 20 "
    "4.0 5.0 0.5 3.9 5.0 0.5 0.1 0.0 0.5 0.3 0.0 1134863808.25 b21 1134863808.26";

TEST(ParseLine, Flaser) {
  const auto parsed = parse_line(flaser_line(180), 7, FlaserGeometry::kStandard);
  const auto* scan = std::get_if<Scan>(&parsed);
  ASSERT_NE(scan, nullptr);
  EXPECT_EQ(scan->type, "FLASER");
  EXPECT_EQ(scan->line, 7);
  EXPECT_EQ(scan->utime, 12'500'000);
  ASSERT_EQ(scan->ranges.size(), 180u);
  EXPECT_FLOAT_EQ(scan->ranges[0], 1.0f);
  EXPECT_FLOAT_EQ(scan->ranges[179], 2.79f);
  EXPECT_DOUBLE_EQ(scan->x_m, 1.5);
  EXPECT_DOUBLE_EQ(scan->y_m, -2.25);
  EXPECT_DOUBLE_EQ(scan->theta_rad, 0.75);
  EXPECT_DOUBLE_EQ(scan->beams.angle_first, -kPi / 2);
  EXPECT_DOUBLE_EQ(scan->beams.angle_step, kPi / 180);
}

TEST(ParseLine, FlaserGeometries) {
  EXPECT_DOUBLE_EQ(flaser_beam_angles(181, FlaserGeometry::kStandard).angle_step, kPi / 180);
  EXPECT_DOUBLE_EQ(flaser_beam_angles(360, FlaserGeometry::kStandard).angle_step, kPi / 360);
  EXPECT_DOUBLE_EQ(flaser_beam_angles(361, FlaserGeometry::kStandard).angle_step, kPi / 360);
  const auto c = flaser_beam_angles(180, FlaserGeometry::kCentered);
  EXPECT_NEAR(c.angle_first + 89.5 * c.angle_step, 0.0, 1e-12);  // symmetric about forward
  const auto r = flaser_beam_angles(180, FlaserGeometry::kReversed);
  EXPECT_LT(r.angle_step, 0.0);
  EXPECT_EQ(parse_flaser_geometry("closed"), FlaserGeometry::kClosed);
  EXPECT_FALSE(parse_flaser_geometry("sideways"));
}

TEST(ParseLine, RobotLaser1UsesTheStatedGeometryAndLaserPose) {
  const auto parsed = parse_line(kRobotLaser, 1, FlaserGeometry::kStandard);
  const auto* scan = std::get_if<Scan>(&parsed);
  ASSERT_NE(scan, nullptr) << std::get<Malformed>(parsed).reason;
  EXPECT_EQ(scan->type, "ROBOTLASER1");
  EXPECT_EQ(scan->ranges, (std::vector<float>{1.0f, 2.0f, 3.0f}));
  EXPECT_DOUBLE_EQ(scan->beams.angle_first, -1.5708);
  EXPECT_DOUBLE_EQ(scan->beams.angle_step, 0.0174533);
  EXPECT_DOUBLE_EQ(*scan->range_max_m, 81.9);
  EXPECT_DOUBLE_EQ(scan->x_m, 4.0);  // laser pose, not robot pose (3.9)
  EXPECT_EQ(scan->utime, 1'134'863'808'250'000);
}

TEST(ParseLine, Odometry) {
  const auto parsed = parse_line("ODOM 0.5 -1.25 0.3 0.4 -0.1 0 976052857.337284 host 0.25", 3, {});
  const auto* odom = std::get_if<Odometry>(&parsed);
  ASSERT_NE(odom, nullptr) << std::get<Malformed>(parsed).reason;
  EXPECT_EQ(odom->line, 3);
  EXPECT_DOUBLE_EQ(odom->x_m, 0.5);
  EXPECT_DOUBLE_EQ(odom->y_m, -1.25);
  EXPECT_DOUBLE_EQ(odom->theta_rad, 0.3);
  EXPECT_DOUBLE_EQ(odom->tv_mps, 0.4);
  EXPECT_DOUBLE_EQ(odom->rv_radps, -0.1);
  EXPECT_EQ(odom->stamp.ipc_utime, 976'052'857'337'284);  // exact, from the digits
  EXPECT_DOUBLE_EQ(odom->stamp.ipc_quantum_s, 1e-6);
  EXPECT_EQ(odom->stamp.logger_utime, 250'000);
  for (const char* bad : {"ODOM 1 2", "ODOM 0 0 0 0 0 0 1.0 h", "ODOM 0 0 nan 0 0 0 1.0 h 1.0",
                          "ODOM 0 0 0 x 0 0 1.0 h 1.0", "ODOM 0 0 0 0 0 0 1e300 h 1.0",
                          "ODOM 0 0 0 0 0 0 1.0 h 1.0 extra"}) {
    EXPECT_TRUE(std::holds_alternative<Malformed>(parse_line(bad, 1, {}))) << bad;
  }
}

TEST(ParseLine, OtherTypesCommentsAndBlanks) {
  EXPECT_EQ(std::get<OtherMessage>(parse_line("PARAM a b", 1, {})).type, "PARAM");
  EXPECT_TRUE(std::holds_alternative<Ignorable>(parse_line("# comment", 1, {})));
  EXPECT_TRUE(std::holds_alternative<Ignorable>(parse_line("   \t\r", 1, {})));
  EXPECT_TRUE(std::holds_alternative<Ignorable>(parse_line("", 1, {})));
}

bool malformed(const std::string& line) {
  return std::holds_alternative<Malformed>(parse_line(line, 1, FlaserGeometry::kStandard));
}

TEST(ParseLine, RejectsBadFlaserLines) {
  EXPECT_TRUE(malformed("FLASER"));
  EXPECT_TRUE(malformed("FLASER 0 1 2 3 0 0 0 1.0 h 1.0"));
  EXPECT_TRUE(malformed("FLASER -3 1 2 3"));
  EXPECT_TRUE(malformed("FLASER 3.5 1 2 3"));
  EXPECT_TRUE(malformed("FLASER abc 1 2 3"));
  EXPECT_TRUE(malformed("FLASER 999999999999 1 2 3 0 0 0 0 0 0 1.0 h 1.0"));
  EXPECT_TRUE(malformed("FLASER 2147483647 1 2 3 0 0 0 0 0 0 1.0 h 1.0"));
  EXPECT_TRUE(malformed("FLASER 100000 1 2 3 0 0 0 0 0 0 1.0 h 1.0"));
  EXPECT_TRUE(malformed("FLASER 4 1 2 3 0 0 0 0 0 0 1.0 h 1.0"));  // one range short
  std::string line = flaser_line(3);
  EXPECT_FALSE(malformed(line));
  EXPECT_TRUE(malformed(line + " extra extra extra"));
  for (const char* bad : {"nan", "NaN", "inf", "-inf", "1e999", "1.0.0", "x", "0x10", ""}) {
    EXPECT_TRUE(malformed(std::string("FLASER 3 1 ") + bad + " 3 0 0 0 0 0 0 1.0 h 1.0")) << bad;
    EXPECT_TRUE(malformed(std::string("FLASER 3 1 2 3 ") + bad + " 0 0 0 0 0 1.0 h 1.0")) << bad;
  }
  EXPECT_TRUE(malformed("FLASER 3 1 -1 3 0 0 0 0 0 0 1.0 h 1.0"));  // negative range
  EXPECT_TRUE(malformed(flaser_line(3, "nan")));
  EXPECT_TRUE(malformed(flaser_line(3, "1e300")));  // would overflow microseconds
  EXPECT_TRUE(malformed("FL\x01SER 3 1 2 3"));
  EXPECT_TRUE(malformed("flaser 3 1 2 3"));
}

TEST(ParseLine, EveryTruncationOfAGoodLineIsHandled) {
  for (const std::string& line : {flaser_line(5), kRobotLaser}) {
    const std::size_t type_end = line.find(' '), last_field = line.rfind(' ') + 1;
    for (std::size_t cut = 0; cut < line.size(); ++cut) {
      const auto parsed = parse_line(std::string_view(line).substr(0, cut), 1, {});
      // Only a cut inside the last field (the unused logger timestamp) leaves a complete line.
      if (std::holds_alternative<Scan>(parsed)) {
        EXPECT_GT(cut, last_field) << cut;
      }
      // A cut type name ("FLAS") reads as some other message type, skipped and counted.
      if (cut > type_end && cut <= last_field) {
        EXPECT_TRUE(std::holds_alternative<Malformed>(parsed)) << cut;
      }
    }
  }
}

TEST(ParseLine, SurvivesRandomBytes) {
  std::mt19937 rng(42);
  int scans = 0;
  for (int i = 0; i < 5000; ++i) {
    std::string junk(rng() % 300, '\0');
    for (char& c : junk) c = static_cast<char>(rng() % 256);
    if (i % 2) junk = "FLASER " + std::to_string(rng() % 5) + " " + junk;  // junk after a type
    scans += std::holds_alternative<Scan>(parse_line(junk, i, FlaserGeometry::kStandard));
  }
  EXPECT_EQ(scans, 0);
}

std::filesystem::path temp_file(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("traverse-carmen-test-" + std::to_string(::getpid()) + "-" + name);
}

void write_gz(const std::filesystem::path& path, const std::string& text) {
  gzFile f = gzopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(gzwrite(f, text.data(), static_cast<unsigned>(text.size())),
            static_cast<int>(text.size()));
  gzclose(f);
}

TEST(Reader, CountsScansSkipsOtherTypesAndListsMalformedLines) {
  const std::string text = "# header\n" + flaser_line(4) + "\nODOM 0 0 0 0 0 0 1 h 1\n" +
                           "FLASER 4 1 2\n" + std::string("\x00\xff\x10 junk", 9) + "\n\n" +
                           flaser_line(4, "13.0") + "\nPARAM x y\nFLASER nan\n" +
                           flaser_line(4, "14.0");
  const auto path = temp_file("mixed.log");
  std::ofstream(path, std::ios::binary) << text;
  for (const auto& p : {path, std::filesystem::path(path.string() + ".gz")}) {
    if (p != path) write_gz(p, text);
    Reader reader(p.string());
    ASSERT_TRUE(reader.good());
    std::vector<int64_t> lines, utimes, odometry_lines;
    while (auto record = reader.next_record()) {
      if (const auto* scan = std::get_if<Scan>(&*record)) {
        lines.push_back(scan->line);
        utimes.push_back(scan->utime);
      } else {
        odometry_lines.push_back(std::get<OdometryReading>(*record).odom.line);
      }
    }
    EXPECT_EQ(lines, (std::vector<int64_t>{2, 7, 10})) << p;
    EXPECT_EQ(odometry_lines, (std::vector<int64_t>{3}));
    EXPECT_EQ(utimes, (std::vector<int64_t>{12'500'000, 13'000'000, 14'000'000}));
    const Summary& s = reader.summary();
    EXPECT_EQ(s.lines, 10);  // the last line has no newline and still counts
    EXPECT_EQ(s.scans, 3);
    EXPECT_EQ(s.malformed_lines, (std::vector<int64_t>{4, 5, 9}));
    EXPECT_EQ(s.malformed_count, 3);
    EXPECT_EQ(s.odometry, 1);
    EXPECT_EQ(s.skipped_by_type.size(), 1u);
    EXPECT_EQ(s.skipped_by_type.at("PARAM"), 1);
    EXPECT_EQ(s.comment_or_blank_lines, 2);
    EXPECT_TRUE(s.input_error.empty()) << s.input_error;
    std::filesystem::remove(p);
  }
}

// A few scans out of order in a log whose stamps carry time (intel has 4 of 910): kept in file
// order, each 1 us after the one before.
TEST(Reader, TimeNeverGoesBackwards) {
  const auto path = temp_file("backwards.log");
  std::ofstream(path) << flaser_line(2, "10") << "\n"
                      << flaser_line(2, "9") << "\n"
                      << flaser_line(2, "9") << "\n"
                      << flaser_line(2, "11") << "\n"
                      << flaser_line(2, "12") << "\n"
                      << flaser_line(2, "13") << "\n"
                      << flaser_line(2, "14") << "\n"
                      << flaser_line(2, "15") << "\n"
                      << flaser_line(2, "16") << "\n";
  Reader reader(path.string());
  std::vector<int64_t> utimes;
  while (auto scan = reader.next()) utimes.push_back(scan->utime);
  EXPECT_EQ(utimes,
            (std::vector<int64_t>{10'000'000, 10'000'001, 10'000'002, 11'000'000, 12'000'000,
                                  13'000'000, 14'000'000, 15'000'000, 16'000'000}));
  EXPECT_EQ(reader.summary().time.clock, Clock::kIpc);
  EXPECT_EQ(reader.summary().backwards_count, 2);
  EXPECT_EQ(reader.summary().backwards_lines, (std::vector<int64_t>{2, 3}));
  EXPECT_EQ(reader.summary().max_backstep_us, 1'000'001);
  std::filesystem::remove(path);
}

TEST(PrintedQuantum, IsThePlaceValueOfTheLastDigit) {
  EXPECT_DOUBLE_EQ(printed_quantum("1.13486e+09"), 1e4);
  EXPECT_DOUBLE_EQ(printed_quantum("32.9068"), 1e-4);
  EXPECT_DOUBLE_EQ(printed_quantum("1134863808.25"), 1e-2);
  EXPECT_DOUBLE_EQ(printed_quantum("7"), 1.0);
  EXPECT_DOUBLE_EQ(printed_quantum("1.5E3"), 100.0);
  EXPECT_DOUBLE_EQ(printed_quantum("2.5e-3"), 1e-4);
}

// Timestamps printed with 6 significant digits (csail): all scans share one value. They are
// spaced at the nominal period from the first, or timed by the logger's clock when that is
// printed finely.
TEST(Reader, QuantisedTimestampsAreSpaced) {
  const auto path = temp_file("quantised.log");
  std::ofstream(path) << flaser_line(2, "1.13486e+09") << "\n"
                      << flaser_line(2, "1.13486e+09") << "\n"
                      << flaser_line(2, "1.13486e+09") << "\n"
                      << flaser_line(2, "1.13487e+09") << "\n";
  Reader reader(path.string(), FlaserGeometry::kStandard, {1.0, 2.5});
  std::vector<int64_t> utimes;
  while (auto scan = reader.next()) utimes.push_back(scan->utime);
  const int64_t t0 = 1'134'860'000'000'000;
  EXPECT_EQ(utimes, (std::vector<int64_t>{t0, t0 + 2'500'000, t0 + 5'000'000, t0 + 7'500'000}));
  EXPECT_EQ(reader.summary().quantised_count, 4);
  EXPECT_EQ(reader.summary().time.clock, Clock::kNominal);
  EXPECT_EQ(reader.summary().restamped_nominal, 4);  // from the first (coarse) stamp
  EXPECT_EQ(reader.summary().restamped_logger, 0);
  EXPECT_EQ(reader.summary().backwards_count, 0);
  EXPECT_DOUBLE_EQ(reader.summary().max_quantum_s, 1e4);
  std::filesystem::remove(path);

  // A fine logger timestamp (the line's last field) is used instead.
  auto with_logger = [](const std::string& logger) {
    std::string line = flaser_line(2, "1.13486e+09");
    return line.substr(0, line.rfind(' ') + 1) + logger;
  };
  std::ofstream(path) << with_logger("1134860000.5") << "\n"
                      << with_logger("1134860003.25") << "\n";
  Reader logged(path.string());
  utimes.clear();
  while (auto scan = logged.next()) utimes.push_back(scan->utime);
  EXPECT_EQ(utimes, (std::vector<int64_t>{1'134'860'000'500'000, 1'134'860'003'250'000}));
  EXPECT_EQ(logged.summary().restamped_logger, 2);
  EXPECT_EQ(logged.summary().restamped_nominal, 0);
  std::filesystem::remove(path);
}

TEST(Reader, FineTimestampsAreKept) {
  const auto path = temp_file("fine.log");
  std::ofstream(path) << flaser_line(2, "32.9068") << "\n" << flaser_line(2, "35.1051") << "\n";
  Reader reader(path.string());
  std::vector<int64_t> utimes;
  while (auto scan = reader.next()) utimes.push_back(scan->utime);
  EXPECT_EQ(utimes, (std::vector<int64_t>{32'906'800, 35'105'100}));
  EXPECT_EQ(reader.summary().quantised_count, 0);
  std::filesystem::remove(path);
}

// The real csail log: 406 scans within two printed values; spaced, every scan has its own time.
TEST(Reader, CsailScansGetDistinctSpacedTimes) {
  const std::string path = "../shared/data/carmen/csail-corrected.log.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "no data at " << path;
  Reader reader(path);
  std::vector<int64_t> utimes;
  while (auto scan = reader.next()) utimes.push_back(scan->utime);
  ASSERT_GT(utimes.size(), 400u);
  for (std::size_t i = 1; i < utimes.size(); ++i) {
    ASSERT_GE(utimes[i] - utimes[i - 1], 1'000'000) << "scan " << i;
  }
  EXPECT_EQ(reader.summary().quantised_count, static_cast<int64_t>(utimes.size()));
  EXPECT_EQ(reader.summary().backwards_count, 0);
}

TEST(Reader, AHugeLineIsMalformedAndReadingGoesOn) {
  const auto path = temp_file("huge.log");
  {
    std::ofstream out(path, std::ios::binary);
    out << "FLASER 3";
    for (std::size_t i = 0; i < kMaxLineBytes / 4 + 10; ++i) out << " 1.5";
    out << "\n" << flaser_line(3) << "\n";
  }
  Reader reader(path.string());
  const auto scan = reader.next();
  ASSERT_TRUE(scan);
  EXPECT_EQ(scan->line, 2);
  EXPECT_FALSE(reader.next());
  EXPECT_EQ(reader.summary().malformed_lines, (std::vector<int64_t>{1}));
  EXPECT_EQ(reader.summary().first_malformed_reason, "line longer than 1 MiB");
  // The same line last in the file, without a newline, is still counted.
  std::filesystem::resize_file(path, kMaxLineBytes + 10);
  Reader at_end(path.string());
  EXPECT_FALSE(at_end.next());
  EXPECT_EQ(at_end.summary().malformed_lines, (std::vector<int64_t>{1}));
  std::filesystem::remove(path);
}

TEST(Reader, TruncatedGzipKeepsWhatWasReadAndReportsTheDamage) {
  std::string text;
  for (int i = 0; i < 2000; ++i) text += flaser_line(180, std::to_string(i)) + "\n";
  const auto path = temp_file("cut.log.gz");
  write_gz(path, text);
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size / 2);
  Reader reader(path.string());
  int64_t scans = 0, last_utime = -1'000'000;
  while (auto scan = reader.next()) {
    EXPECT_EQ(scan->utime, last_utime + 1'000'000);
    last_utime = scan->utime;
    ++scans;
  }
  EXPECT_GT(scans, 100);
  EXPECT_LT(scans, 2000);
  EXPECT_EQ(reader.summary().malformed_count, 0);  // the cut last line is dropped, not parsed
  EXPECT_FALSE(reader.summary().input_error.empty());
  std::filesystem::remove(path);
}

TEST(Reader, MissingFileIsNotGood) {
  Reader reader("/nonexistent/dir/file.log");
  EXPECT_FALSE(reader.good());
  EXPECT_FALSE(reader.next());
  EXPECT_FALSE(reader.summary().input_error.empty());
}

}  // namespace
}  // namespace traverse::carmen
