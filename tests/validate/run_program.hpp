// Runs a built program and captures its standard output and exit code (tests only).
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace traverse::test {

struct ProgramResult {
  int exit_code = -1;
  std::string out;  // standard output

  // The last non-empty line (the JSON summary of the tools).
  std::string last_line() const {
    std::size_t end = out.find_last_not_of('\n');
    if (end == std::string::npos) return "";
    const std::size_t begin = out.rfind('\n', end);
    return out.substr(begin == std::string::npos ? 0 : begin + 1,
                      end - (begin == std::string::npos ? 0 : begin + 1) + 1);
  }
};

inline ProgramResult run_program(const std::string& command) {
  ProgramResult r;
  FILE* p = popen((command + " 2>/dev/null").c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline std::string quoted(const std::string& s) { return "'" + s + "'"; }

}  // namespace traverse::test
