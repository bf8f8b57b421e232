// traverse-validate LOG: checks an LCM log file channel by channel and prints a table, the damage
// found (with byte offsets) and one JSON summary line last.
// Exit 0: the log is clean; 1: it has problems; 2: bad usage or unreadable file.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "log_validation.hpp"
#include "version.hpp"

int main(int argc, char** argv) {
  CLI::App app(
      "Checks an LCM log: per channel message count, mean rate, largest gap, timestamps going "
      "backwards, sequence gaps and decode failures (type told by the LCM fingerprint); damage "
      "with its byte offset. Prints a JSON summary as the last line. Exit 0 when clean, 1 when "
      "the log has problems, 2 on bad usage or an unreadable file.",
      "traverse-validate");
  std::string path;
  bool json_only = false;
  app.add_option("LOG", path, "LCM log file")->required();
  app.add_flag("--json-only", json_only, "print only the JSON summary line");
  traverse::add_version_flag(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    std::fprintf(stderr, "traverse-validate: not a readable file: %s\n", path.c_str());
    return 2;
  }
  try {
    const auto v = traverse::validate::validate_log(path);
    if (!json_only) std::fputs(traverse::validate::to_text(v).c_str(), stdout);
    std::puts(traverse::validate::to_json(v).c_str());
    return v.ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "traverse-validate: %s\n", e.what());
    return 2;
  }
}
