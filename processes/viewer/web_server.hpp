// Serves the operator's page and streams to it, on a thread of its own, with Boost.Beast (HTTP and
// WebSocket over Boost.Asio; Debian's libboost-dev, header-only): GET of a file under web_root
// (the page, three.js), and a WebSocket at /ws that carries the frames of frames.hpp.
//
// The side that feeds it (the viewer's LCM loop) never waits for a browser: broadcast() and
// send_snapshot() only append to each browser's queue under a mutex, and this server's thread
// writes the queues out. A queue is bounded (queue_bytes): a browser that is slow or gone and
// lets it fill loses its queued frames (counted as dropped) and is owed a snapshot, which it gets
// once what it has in flight is written; until then it is sent nothing more. A new browser is owed
// a snapshot too. So a browser shows either everything or a state that catches up, never a cloud
// with holes, and the memory per browser is bounded by queue_bytes and one snapshot.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>  // before Boost 1.74's Asio (web_server.cpp), whose awaitable.hpp needs
                    // std::exchange in C++20 without including it
#include <vector>

#include "frames.hpp"

namespace traverse::viewer {

class WebServer {
 public:
  struct Options {
    std::string address = "127.0.0.1";
    int port = 0;  // 0: any free port (port() says which)
    std::string web_root;
    int64_t queue_bytes = 16 << 20;  // [bytes] per browser
  };
  struct Counters {
    int64_t clients = 0;         // connected now
    int64_t connections = 0;     // WebSocket connections accepted since start
    int64_t http_requests = 0;   // files asked for
    int64_t http_not_found = 0;  // ... of which not served (missing, or outside web_root)
    int64_t frames_sent = 0, bytes_sent = 0;
    int64_t frames_dropped = 0, bytes_dropped = 0;  // dropped from full queues
    int64_t snapshots = 0;         // snapshots queued (new browsers and those that fell behind)
    int64_t client_messages = 0;   // messages browsers sent (read and ignored)
    int64_t queued_bytes_max = 0;  // [bytes] largest queue of any browser
  };

  // Binds and listens (throws std::runtime_error saying why not) and starts its thread.
  explicit WebServer(const Options& options);
  ~WebServer();  // closes every connection and stops the thread
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  int port() const;
  // Queues frames for every browser in sync (not owed a snapshot).
  void broadcast(const std::vector<Frame>& frames);
  // True when a browser is owed a snapshot and has nothing queued.
  bool snapshot_wanted() const;
  // Queues `frames` (a whole snapshot) for every browser owed one with nothing queued.
  void send_snapshot(const std::vector<Frame>& frames);
  Counters counters() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace traverse::viewer
