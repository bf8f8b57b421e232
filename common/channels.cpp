#include "channels.hpp"

#include <algorithm>
#include <cctype>

namespace traverse::channels {

std::string status_channel(const std::string& process_name) {
  std::string upper = process_name;
  std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) {
    return std::isalnum(c) ? static_cast<char>(std::toupper(c)) : '_';
  });
  return "STATUS_" + upper;
}

std::string full_channel(const std::string& channel) { return channel + "_FULL"; }

}  // namespace traverse::channels
