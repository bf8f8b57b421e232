#include "web_server.hpp"

#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace traverse::viewer {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;

namespace {

// The types the page is made of; anything else is not served.
const char* content_type(const std::string& extension) {
  static const std::map<std::string, const char*> types{{".html", "text/html; charset=utf-8"},
                                                        {".js", "text/javascript; charset=utf-8"},
                                                        {".mjs", "text/javascript; charset=utf-8"},
                                                        {".css", "text/css; charset=utf-8"},
                                                        {".json", "application/json"},
                                                        {".png", "image/png"},
                                                        {".svg", "image/svg+xml"}};
  auto it = types.find(extension);
  return it == types.end() ? nullptr : it->second;
}

}  // namespace

class WsSession;

struct WebServer::Impl {
  Options options;
  net::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  std::thread thread;
  mutable std::mutex mutex;  // the sessions' queues and the counters
  std::map<uint64_t, std::shared_ptr<WsSession>> sessions;
  uint64_t next_id = 0;
  Counters counters;

  void accept();
  void serve(tcp::socket socket);
  std::optional<std::string> file(const std::string& target, std::string& type) const;
};

// One browser's WebSocket: a queue of frames written out one at a time on the server's thread.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(WebServer::Impl& server, uint64_t id, beast::tcp_stream&& stream)
      : server_(server), id_(id), ws_(std::move(stream)) {}

  void start(http::request<http::string_body> request) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(64 * 1024);
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      {
        std::lock_guard lock(self->server_.mutex);
        self->server_.sessions[self->id_] = self;
        ++self->server_.counters.connections;
      }
      self->read();
    });
  }

  // With the server's mutex held. A frame that would overflow the queue (a snapshot never does)
  // drops it all and owes the browser a snapshot.
  void push(const Frame& f, bool snapshot) {
    WebServer::Counters& c = server_.counters;
    if (!snapshot && queued_bytes_ + static_cast<int64_t>(f.size()) > server_.options.queue_bytes) {
      c.frames_dropped += static_cast<int64_t>(queue_.size()) + 1;
      c.bytes_dropped += queued_bytes_ + static_cast<int64_t>(f.size());
      queue_.clear();
      queued_bytes_ = 0;
      owed_snapshot = true;
      return;
    }
    queue_.push_back(f);
    queued_bytes_ += static_cast<int64_t>(f.size());
    c.queued_bytes_max = std::max(c.queued_bytes_max, queued_bytes_);
    if (!writing_) {
      writing_ = true;
      net::post(server_.ioc, [self = shared_from_this()] { self->write(); });
    }
  }
  bool drained() const { return queue_.empty() && !writing_; }
  bool owed_snapshot = true;

 private:
  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) return self->close();
      self->buffer_.consume(self->buffer_.size());
      {
        std::lock_guard lock(self->server_.mutex);
        ++self->server_.counters.client_messages;
      }
      self->read();
    });
  }
  void write() {
    {
      std::lock_guard lock(server_.mutex);
      if (queue_.empty()) {
        writing_ = false;
        return;
      }
      in_flight_ = std::move(queue_.front());
      queue_.pop_front();
      queued_bytes_ -= static_cast<int64_t>(in_flight_.size());
    }
    ws_.binary(in_flight_.binary);
    ws_.async_write(net::buffer(*in_flight_.data),
                    [self = shared_from_this()](beast::error_code ec, std::size_t n) {
                      if (ec) return self->close();
                      {
                        std::lock_guard lock(self->server_.mutex);
                        ++self->server_.counters.frames_sent;
                        self->server_.counters.bytes_sent += static_cast<int64_t>(n);
                      }
                      self->write();
                    });
  }
  void close() {
    std::lock_guard lock(server_.mutex);
    server_.sessions.erase(id_);
    queue_.clear();
    queued_bytes_ = 0;
  }

  WebServer::Impl& server_;
  uint64_t id_;
  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer buffer_;
  std::deque<Frame> queue_;
  int64_t queued_bytes_ = 0;
  bool writing_ = false;
  Frame in_flight_;
};

// One HTTP connection: files, or the upgrade to a WebSocket at /ws.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(WebServer::Impl& server, tcp::socket&& socket)
      : server_(server), stream_(std::move(socket)) {}

  void read() {
    request_ = {};
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, request_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) {
                       if (ec) return;
                       self->handle();
                     });
  }

 private:
  void handle() {
    if (websocket::is_upgrade(request_)) {
      if (request_.target() != "/ws") return;  // closes the connection
      stream_.expires_never();
      uint64_t id;
      {
        std::lock_guard lock(server_.mutex);
        id = server_.next_id++;
      }
      std::make_shared<WsSession>(server_, id, std::move(stream_))->start(std::move(request_));
      return;
    }
    auto response = std::make_shared<http::response<http::string_body>>();
    response->version(request_.version());
    response->keep_alive(request_.keep_alive());
    std::string type;
    std::optional<std::string> body;
    if (request_.method() == http::verb::get || request_.method() == http::verb::head) {
      body = server_.file(std::string(request_.target()), type);
    }
    {
      std::lock_guard lock(server_.mutex);
      ++server_.counters.http_requests;
      if (!body) ++server_.counters.http_not_found;
    }
    if (body) {
      response->result(http::status::ok);
      response->set(http::field::content_type, type);
      response->set(http::field::cache_control, "no-cache");
      if (request_.method() == http::verb::get) response->body() = std::move(*body);
    } else {
      response->result(http::status::not_found);
      response->set(http::field::content_type, "text/plain");
      response->body() = "not found\n";
    }
    response->prepare_payload();
    http::async_write(stream_, *response,
                      [self = shared_from_this(), response](beast::error_code ec, std::size_t) {
                        if (!ec && response->keep_alive()) self->read();
                      });
  }

  WebServer::Impl& server_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  http::request<http::string_body> request_;
};

std::optional<std::string> WebServer::Impl::file(const std::string& target,
                                                 std::string& type) const {
  std::string path = target.substr(0, target.find_first_of("?#"));
  if (path.empty() || path[0] != '/' || path.find("..") != std::string::npos ||
      path.find('\\') != std::string::npos) {
    return std::nullopt;
  }
  if (path.back() == '/') path += "index.html";
  const std::filesystem::path p = std::filesystem::path(options.web_root) / path.substr(1);
  const char* t = content_type(p.extension().string());
  std::error_code ec;
  if (!t || !std::filesystem::is_regular_file(p, ec)) return std::nullopt;
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  if (!in) return std::nullopt;
  type = t;
  return s.str();
}

void WebServer::Impl::accept() {
  acceptor.async_accept(net::make_strand(ioc), [this](beast::error_code ec, tcp::socket socket) {
    if (ec == net::error::operation_aborted) return;
    if (!ec) std::make_shared<HttpSession>(*this, std::move(socket))->read();
    accept();
  });
}

WebServer::WebServer(const Options& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  beast::error_code ec;
  const auto address = net::ip::make_address(options.address, ec);
  if (ec) throw std::runtime_error("not an IP address: '" + options.address + "'");
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(options.port));
  tcp::acceptor& a = impl_->acceptor;
  a.open(endpoint.protocol(), ec);
  if (!ec) a.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) a.bind(endpoint, ec);
  if (!ec) a.listen(net::socket_base::max_listen_connections, ec);
  if (ec) {
    throw std::runtime_error("cannot listen on " + options.address + ":" +
                             std::to_string(options.port) + ": " + ec.message());
  }
  impl_->accept();
  impl_->thread = std::thread([this] { impl_->ioc.run(); });
}

WebServer::~WebServer() {
  impl_->ioc.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
  std::lock_guard lock(impl_->mutex);
  impl_->sessions.clear();
}

int WebServer::port() const { return impl_->acceptor.local_endpoint().port(); }

void WebServer::broadcast(const std::vector<Frame>& frames) {
  std::lock_guard lock(impl_->mutex);
  for (auto& [id, s] : impl_->sessions) {
    for (const Frame& f : frames) {
      if (s->owed_snapshot) break;
      s->push(f, false);
    }
  }
}

bool WebServer::snapshot_wanted() const {
  std::lock_guard lock(impl_->mutex);
  for (const auto& [id, s] : impl_->sessions) {
    if (s->owed_snapshot && s->drained()) return true;
  }
  return false;
}

void WebServer::send_snapshot(const std::vector<Frame>& frames) {
  std::lock_guard lock(impl_->mutex);
  for (auto& [id, s] : impl_->sessions) {
    if (!s->owed_snapshot || !s->drained()) continue;
    s->owed_snapshot = false;
    ++impl_->counters.snapshots;
    for (const Frame& f : frames) s->push(f, true);
  }
}

WebServer::Counters WebServer::counters() const {
  std::lock_guard lock(impl_->mutex);
  Counters c = impl_->counters;
  c.clients = static_cast<int64_t>(impl_->sessions.size());
  return c;
}

}  // namespace traverse::viewer
