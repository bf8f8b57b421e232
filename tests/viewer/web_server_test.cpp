// The viewer's web server on a free port of 127.0.0.1: files under web_root only; a browser's
// WebSocket gets a snapshot, then what is broadcast; a browser that does not read never blocks
// broadcast(): its queue is bounded, the overflow is dropped and counted, and once it reads again
// it gets a snapshot; a browser that leaves is forgotten.
#include "web_server.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

namespace traverse::viewer {
namespace {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;

Frame frame(std::string s, bool binary = false) {
  return {std::make_shared<const std::string>(std::move(s)), binary};
}

// Waits (up to 20 s, polling) until `ok()`.
template <class F>
bool eventually(F ok) {
  for (int i = 0; i < 2000; ++i) {
    if (ok()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

// A browser's WebSocket to the server at `port`, opened.
std::unique_ptr<websocket::stream<tcp::socket>> browser(net::io_context& ioc, int port) {
  auto ws = std::make_unique<websocket::stream<tcp::socket>>(ioc);
  ws->next_layer().connect(
      tcp::endpoint(net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  ws->handshake("127.0.0.1", "/ws");
  return ws;
}

class WebServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = std::filesystem::temp_directory_path() /
            ("traverse_web_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(root_ / "sub");
    std::ofstream(root_ / "index.html") << "<html>page</html>";
    std::ofstream(root_ / "sub" / "a.js") << "export const a = 1;";
    std::ofstream(root_ / "secret.txt") << "not served: no page type";
  }
  void TearDown() override { std::filesystem::remove_all(root_); }

  std::unique_ptr<WebServer> start(int64_t queue_bytes = 16 << 20) {
    return std::make_unique<WebServer>(
        WebServer::Options{"127.0.0.1", 0, root_.string(), queue_bytes});
  }
  static std::pair<unsigned, std::string> get(int port, const std::string& target) {
    net::io_context ioc;
    beast::tcp_stream s(ioc);
    s.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
    http::request<http::empty_body> req{http::verb::get, target, 11};
    req.set(http::field::host, "127.0.0.1");
    http::write(s, req);
    beast::flat_buffer b;
    http::response<http::string_body> res;
    http::read(s, b, res);
    return {res.result_int(), res.body()};
  }

  std::filesystem::path root_;
};

TEST_F(WebServerTest, ServesThePageAndNothingElse) {
  auto server = start();
  EXPECT_GT(server->port(), 0);
  EXPECT_EQ(get(server->port(), "/"), std::make_pair(200u, std::string("<html>page</html>")));
  EXPECT_EQ(get(server->port(), "/sub/a.js?v=1").first, 200u);
  EXPECT_EQ(get(server->port(), "/../etc/passwd").first, 404u);
  EXPECT_EQ(get(server->port(), "/sub/../index.html").first, 404u);
  EXPECT_EQ(get(server->port(), "/secret.txt").first, 404u);
  EXPECT_EQ(get(server->port(), "/missing.html").first, 404u);
  EXPECT_EQ(server->counters().http_requests, 6);
  EXPECT_EQ(server->counters().http_not_found, 4);
}

TEST_F(WebServerTest, RefusesAnAddressItCannotListenOn) {
  EXPECT_THROW(WebServer(WebServer::Options{"not-an-address", 0, root_.string(), 1 << 20}),
               std::runtime_error);
  auto server = start();
  EXPECT_THROW(WebServer(WebServer::Options{"127.0.0.1", server->port(), root_.string(), 1 << 20}),
               std::runtime_error);
}

TEST_F(WebServerTest, StreamsASnapshotThenChangesAndForgetsALeavingBrowser) {
  auto server = start();
  net::io_context ioc;
  auto socket = browser(ioc, server->port());
  auto& ws = *socket;
  ASSERT_TRUE(eventually([&] { return server->snapshot_wanted(); }));
  server->broadcast({frame("before the snapshot")});  // not for a browser owed one
  server->send_snapshot({frame("reset"), frame("all", true)});
  server->broadcast({frame("change")});
  beast::flat_buffer b;
  std::vector<std::pair<std::string, bool>> got;
  for (int i = 0; i < 3; ++i) {
    ws.read(b);
    got.emplace_back(beast::buffers_to_string(b.data()), ws.got_binary());
    b.consume(b.size());
  }
  EXPECT_EQ(got, (std::vector<std::pair<std::string, bool>>{
                     {"reset", false}, {"all", true}, {"change", false}}));
  EXPECT_FALSE(server->snapshot_wanted());
  EXPECT_EQ(server->counters().clients, 1);
  ws.close(websocket::close_code::normal);
  EXPECT_TRUE(eventually([&] { return server->counters().clients == 0; }));
  EXPECT_EQ(server->counters().connections, 1);
  EXPECT_EQ(server->counters().frames_dropped, 0);
}

TEST_F(WebServerTest, ABrowserThatDoesNotReadIsDroppedNotWaitedFor) {
  constexpr int64_t kQueue = 1 << 20;
  auto server = start(kQueue);
  net::io_context ioc;
  auto socket = browser(ioc, server->port());
  auto& ws = *socket;
  ASSERT_TRUE(eventually([&] { return server->snapshot_wanted(); }));
  server->send_snapshot({frame("reset")});
  // 64 MB broadcast to a browser that reads nothing: far more than the socket buffers and the
  // queue hold. broadcast() returns every time; the overflow is dropped and counted.
  const std::string big(256 * 1024, 'x');
  for (int i = 0; i < 256; ++i) server->broadcast({frame(big, true)});
  const WebServer::Counters c = server->counters();
  EXPECT_GT(c.frames_dropped, 0);
  EXPECT_GT(c.bytes_dropped, 0);
  EXPECT_LE(c.queued_bytes_max, kQueue);
  // Reading again, it gets what was in flight (the overflow may have dropped the first snapshot
  // too, if it was still queued), then is owed a snapshot and gets it.
  beast::flat_buffer b;
  std::atomic<bool> snapshot_read{false};
  std::thread reader([&] {
    beast::error_code ec;
    while (!ec && !snapshot_read) {
      ws.read(b, ec);
      if (!ec && beast::buffers_to_string(b.data()) == "snapshot") snapshot_read = true;
      b.consume(b.size());
    }
  });
  const bool wanted = eventually([&] { return server->snapshot_wanted(); });
  if (wanted) server->send_snapshot({frame("snapshot")});
  EXPECT_TRUE(wanted);
  EXPECT_TRUE(eventually([&] { return snapshot_read.load(); }));
  if (!snapshot_read) {
    beast::error_code ec;
    ws.next_layer().shutdown(tcp::socket::shutdown_both, ec);  // wakes the reader
  }
  reader.join();
  EXPECT_EQ(server->counters().snapshots, 2);
}

}  // namespace
}  // namespace traverse::viewer
