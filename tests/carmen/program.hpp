// Running traverse-carmen from tests and reading what it wrote.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "lcm_log.hpp"

namespace traverse::carmen::test {

inline const std::string kCarmen = std::string(TRAVERSE_BIN_DIR) + "/traverse-carmen";

struct Result {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

inline Result run(const std::string& command) {
  Result r;
  FILE* pipe = popen(("timeout 120 " + command + " 2>&1").c_str(), "r");
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), pipe)) {
    r.output.append(buf.data(), n);
  }
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline std::string last_line(const std::string& s) {
  const auto end = s.find_last_not_of('\n');
  const auto start = s.rfind('\n', end);
  return s.substr(start == std::string::npos ? 0 : start + 1, end - start);
}

// A fresh directory per test, removed by the caller.
inline std::filesystem::path temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("traverse-carmen-prog-" + std::to_string(getpid()) + "-" + name);
  std::filesystem::create_directories(dir);
  return dir;
}

// Every message of type T on `channel` of an LCM log, decoded (a failure to decode fails the test).
template <class T>
std::vector<T> read_channel(const std::string& lcm_log, const std::string& channel) {
  std::vector<T> out;
  LogReader reader(lcm_log);
  while (auto ev = reader.next()) {
    if (ev->channel != channel) continue;
    T msg;
    const int size = static_cast<int>(ev->data.size());
    EXPECT_EQ(msg.decode(ev->data.data(), 0, size), size) << channel;
    out.push_back(msg);
  }
  EXPECT_TRUE(reader.damage().empty()) << lcm_log;
  return out;
}

}  // namespace traverse::carmen::test
