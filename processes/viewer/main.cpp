// traverse-viewer: the operator's live view in a web browser (issue 26). Listens to the mapper's
// preview points, the corrected trajectory, the annotator's colours, the newest pose and every
// process's status, and serves a page (three.js) that draws them, streaming changes over a
// WebSocket. Bound to 127.0.0.1 by default (address and port in its config).
#include <spdlog/spdlog.h>

#include <filesystem>

#include "process.hpp"
#include "viewer_node.hpp"
#include "web_server.hpp"

int main(int argc, char** argv) {
  traverse::Process proc("viewer",
                         "Live operator view: the growing cloud in accuracy colours, the "
                         "trajectory, guidance and every process's status, in a web browser");
  traverse::viewer::ViewerConfig config;
  int port = -1;
  proc.cli().add_option("--port", port, "HTTP port (overrides port of the config; 0: any free)");
  if (auto rc = proc.start(argc, argv, config)) return *rc;  // validate(config) included
  if (port >= 0) config.port = port;
  const std::filesystem::path root = config.web_root.empty() ? TRAVERSE_WEB_ROOT : config.web_root;
  for (const char* f : {"index.html", "node_modules/three/build/three.module.js"}) {
    if (!std::filesystem::is_regular_file(root / f)) {
      spdlog::error(
          "viewer: {} is missing: the page is built into the build tree by the build (three.js "
          "from the npm registry: `npm ci` in processes/viewer/web); rebuild, or set web_root",
          (root / f).string());
      return 1;
    }
  }
  std::unique_ptr<traverse::viewer::WebServer> server;
  try {
    server = std::make_unique<traverse::viewer::WebServer>(traverse::viewer::WebServer::Options{
        config.address, config.port, root.string(), config.client_queue_bytes});
  } catch (const std::exception& e) {
    spdlog::error("viewer: {}", e.what());
    return 1;
  }
  const std::string host = config.address == "0.0.0.0" ? "localhost" : config.address;
  spdlog::info("viewer: open http://{}:{}/ in a browser", host, server->port());
  traverse::viewer::ViewerNode node(
      proc.bus(), config, server.get(),
      [&proc](const std::string& name, double v) { proc.counter(name) = v; });
  const int rc = proc.spin([&node] {
    node.update(traverse::now_utime());
    node.report_counters();
  });
  node.report_counters();
  proc.publish_status("stopped");
  return rc;
}
