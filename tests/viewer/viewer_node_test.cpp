// The viewer node on memq://: the mapper's preview, the densifier's segments, the annotator's
// colours, frontend poses and process statuses reach the scene; malformed messages are counted
// and dropped; a browser connected to its web server gets the whole scene as a snapshot, then the
// changes (a loop closure's moved profiles as poses only, the levels it changed).
#include "viewer_node.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "channels.hpp"
#include "process.hpp"
#include "traverse/process_status_t.hpp"
#include "traverse/resend_request_t.hpp"

namespace traverse::viewer {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000;

dense_segments_t segment(int64_t key, double t0, double t1, double y, int32_t revision) {
  dense_segment_t s{};
  s.key_id_first = key;
  s.key_id_last = key + 1;
  s.revision = revision;
  for (double t = t0; t <= t1 + 1e-9; t += 0.1) {
    s.pose_utime.push_back(kT0 + std::llround(t * 1e6));
    s.x.push_back(t);
    s.y.push_back(y);
    s.theta.push_back(0.0);
  }
  s.n_poses = static_cast<int32_t>(s.x.size());
  dense_segments_t m{};
  m.utime = s.pose_utime.back();
  m.parent_frame = "map";
  m.child_frame = "base";
  m.parts = 1;
  m.segments = {s};
  m.n_segments = 1;
  return m;
}

cloud_preview_t preview(const std::vector<int64_t>& utimes) {
  cloud_preview_t m{};
  m.parent_frame = "map";
  m.cell_m = 0.05;
  for (int64_t t : utimes) {
    preview_profile_t p{};
    p.utime = t;
    p.x_mm = {1000, 2000};
    p.y_mm = {0, 500};
    p.z_mm = {0, 2500};
    p.n_points = 2;
    m.profiles.push_back(p);
    m.utime = t;
  }
  m.n_profiles = static_cast<int32_t>(m.profiles.size());
  return m;
}

annotations_t annotations() {
  annotations_t m{};
  m.utime = kT0 + 1'000'000;
  m.parts = 1;
  m.standard = "USIBD LOA";
  m.coloured_by = "absolute";
  m.bound_method = "exact";
  m.confidence = 0.95;
  for (auto [name, lo, hi] :
       {std::tuple{"LOA30", 0.005, 0.015}, {"LOA20", 0.015, 0.05}, {"LOA10", 0.05, INFINITY}}) {
    accuracy_level_t l{};
    l.name = name;
    l.min_m = lo;
    l.max_m = hi;
    l.accepted = true;
    m.levels.push_back(l);
  }
  m.n_levels = 3;
  m.worst_level = 2;
  for (int i = 0; i < 3; ++i) {
    key_annotation_t k{};
    k.id = i;
    k.utime = kT0 + i * 500'000;
    k.x = 0.5 * i;
    k.level = static_cast<int8_t>(i);
    m.keys.push_back(k);
  }
  m.n_keys = 3;
  return m;
}

class ViewerNodeTest : public ::testing::Test {
 protected:
  void handle_all() {
    while (bus_.lcm().handleTimeout(0) > 0) {
    }
  }
  Bus bus_{"memq://"};
  std::map<std::string, double> counters_;
  dense_segments_t seg0_ = segment(0, 0.0, 1.0, 0.0, 0);
};

TEST_F(ViewerNodeTest, FillsTheSceneAndCountsWhatItDrops) {
  // One bus for both sides: memq:// does not cross instances.
  ViewerNode node(bus_, ViewerConfig{}, nullptr,
                  [this](const std::string& k, double v) { counters_[k] = v; });
  Bus& pub = bus_;
  pub.publish(channels::kDenseSegments, seg0_);
  auto p = preview({kT0 + 200'000, kT0 + 300'000});
  pub.publish(channels::kCloudPreview, p);
  auto a = annotations();
  pub.publish(channels::kAnnotations, a);
  process_status_t st{};
  st.utime = now_utime();
  st.process = "mapper";
  st.state = "running";
  pub.publish(channels::status_channel("mapper"), st);
  // Malformed: bytes that do not hold what they claim, on a preview and a status channel.
  const uint8_t junk[16] = {1, 2, 3, 4, 5, 6, 7, 8, 0x7f, 0xff, 0xff, 0xff, 0, 0, 0, 1};
  bus_.lcm().publish(channels::kCloudPreview, junk, sizeof(junk));
  bus_.lcm().publish(channels::status_channel("backend"), junk, sizeof(junk));
  handle_all();
  node.report_counters();
  EXPECT_EQ(node.scene().profiles().size(), 2u);
  EXPECT_EQ(node.scene().points(), 4);
  EXPECT_TRUE(node.scene().profiles()[0].placed);
  EXPECT_EQ(node.scene().annotations().size(), 3u);
  ASSERT_TRUE(node.scene().legend());
  EXPECT_EQ(node.scene().legend()->levels[1].name, "LOA20");
  EXPECT_EQ(node.board().rows().count("mapper"), 1u);
  EXPECT_EQ(bus_.stats().at(channels::kCloudPreview).decode_failures, 1);
  EXPECT_EQ(counters_.at("STATUS_*/rejected"), 1);
  EXPECT_EQ(counters_.at("statuses"), 1);
  EXPECT_EQ(counters_.at("points"), 4);
}

TEST_F(ViewerNodeTest, AsksForWhatCameBeforeAndTakesTheAnswersOnce) {
  std::vector<std::vector<std::string>> asked;
  bus_.subscribe<resend_request_t>(channels::kResendRequest,
                                   [&](const resend_request_t& m) { asked.push_back(m.channels); });
  ViewerNode node(bus_, ViewerConfig{}, nullptr,
                  [this](const std::string& k, double v) { counters_[k] = v; });
  handle_all();
  ASSERT_EQ(asked.size(), 1u);  // one request naming the three channels
  EXPECT_EQ(asked[0], (std::vector<std::string>{channels::kCloudPreview, channels::kDenseSegments,
                                                channels::kAnnotations}));
  // A profile heard live, then the answers, which hold it again and one from before.
  Bus& pub = bus_;
  auto live = preview({kT0 + 300'000});
  pub.publish(channels::kCloudPreview, live);
  auto before = preview({kT0 + 200'000, kT0 + 300'000});
  pub.publish(channels::full_channel(channels::kCloudPreview), before);
  pub.publish(channels::full_channel(channels::kDenseSegments), seg0_);
  auto a = annotations();
  pub.publish(channels::full_channel(channels::kAnnotations), a);
  handle_all();
  node.report_counters();
  EXPECT_EQ(node.scene().profiles().size(), 2u);
  EXPECT_EQ(node.scene().points(), 4);  // the repeated profile's points once
  EXPECT_EQ(counters_.at("profiles_repeated"), 1);
  EXPECT_EQ(counters_.at("resend_requests_sent"), 1);
  EXPECT_TRUE(node.scene().profiles()[0].placed);
  EXPECT_EQ(node.scene().annotations().size(), 3u);
  EXPECT_EQ(node.scene().polylines().size(), 1u);
}

TEST_F(ViewerNodeTest, DoesNotAskWhenToldNotTo) {
  int asked = 0;
  bus_.subscribe<resend_request_t>(channels::kResendRequest,
                                   [&](const resend_request_t&) { ++asked; });
  ViewerConfig config;
  config.ask_for_state = false;
  ViewerNode node(bus_, config, nullptr);
  handle_all();
  EXPECT_EQ(asked, 0);
}

TEST_F(ViewerNodeTest, ABrowserGetsTheSceneThenTheChanges) {
  namespace net = boost::asio;
  namespace beast = boost::beast;
  const auto root = std::filesystem::temp_directory_path() /
                    ("traverse_viewer_node_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(root);
  WebServer server({"127.0.0.1", 0, root.string(), 16 << 20});
  ViewerConfig config;
  config.update_period_s = 0.01;
  ViewerNode node(bus_, config, &server);
  Bus& pub = bus_;
  pub.publish(channels::kDenseSegments, seg0_);
  auto p = preview({kT0 + 200'000, kT0 + 700'000});
  pub.publish(channels::kCloudPreview, p);
  auto a = annotations();
  pub.publish(channels::kAnnotations, a);
  handle_all();

  net::io_context ioc;
  beast::websocket::stream<net::ip::tcp::socket> ws(ioc);
  ws.next_layer().connect(net::ip::tcp::endpoint(net::ip::make_address("127.0.0.1"),
                                                 static_cast<unsigned short>(server.port())));
  ws.handshake("127.0.0.1", "/ws");
  for (int i = 0; i < 500 && server.counters().clients == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  node.update(now_utime());
  // The snapshot: reset, legend, annotations, trajectory, the two profiles (binary), the current
  // pose (the trajectory's end), status.
  std::vector<std::string> types;
  int profiles = -1;
  beast::flat_buffer b;
  while (types.empty() || types.back() != "status") {
    ws.read(b);
    const std::string data = beast::buffers_to_string(b.data());
    b.consume(b.size());
    if (ws.got_binary()) {
      ASSERT_EQ(data[0], 1);  // profiles
      uint32_t n;
      std::memcpy(&n, data.data() + 1, 4);
      profiles = static_cast<int>(n);
      types.push_back("profiles");
    } else {
      types.push_back(nlohmann::json::parse(data).at("type"));
    }
  }
  EXPECT_EQ(types, (std::vector<std::string>{"reset", "legend", "annotations", "trajectory",
                                             "profiles", "pose", "status"}));
  EXPECT_EQ(profiles, 2);
  // A loop closure moves the segment: the browser gets the profiles' new poses only.
  auto moved = segment(0, 0.0, 1.0, 0.3, 1);
  pub.publish(channels::kDenseSegments, moved);
  handle_all();
  node.update(now_utime() + 1'000'000);
  bool poses = false;
  for (int i = 0; i < 5 && !poses; ++i) {
    ws.read(b);
    const std::string data = beast::buffers_to_string(b.data());
    b.consume(b.size());
    if (!ws.got_binary()) continue;
    ASSERT_EQ(data[0], 2);  // poses, not points
    uint32_t n;
    std::memcpy(&n, data.data() + 1, 4);
    EXPECT_EQ(n, 2u);
    float y;
    std::memcpy(&y, data.data() + 5 + 8, 4);  // first record: u32 index, f32 x, f32 y
    EXPECT_FLOAT_EQ(y, 0.3f);
    poses = true;
  }
  EXPECT_TRUE(poses);
  // The annotator republishes what the closure changed: key pose 2 from LOA10 to LOA30. The
  // browser gets that annotation (the page recolours the points nearest to it in time).
  annotations_t closure = annotations();
  closure.reason = annotations_t::REASON_LOOP_CLOSURE;
  closure.keys.resize(1);
  closure.keys[0] = a.keys[2];
  closure.keys[0].level = 0;
  closure.n_keys = 1;
  pub.publish(channels::kAnnotations, closure);
  handle_all();
  node.update(now_utime() + 2'000'000);
  bool recoloured = false;
  for (int i = 0; i < 5 && !recoloured; ++i) {
    ws.read(b);
    const std::string data = beast::buffers_to_string(b.data());
    b.consume(b.size());
    if (ws.got_binary()) continue;
    const nlohmann::json j = nlohmann::json::parse(data);
    if (j.at("type") != "annotations") continue;
    ASSERT_EQ(j.at("keys").size(), 1u);
    EXPECT_EQ(j.at("keys")[0][0], 2);  // id
    EXPECT_EQ(j.at("keys")[0][4], 0);  // level
    recoloured = true;
  }
  EXPECT_TRUE(recoloured);
  std::filesystem::remove_all(root);
}

}  // namespace
}  // namespace traverse::viewer
