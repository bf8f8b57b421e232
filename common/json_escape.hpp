// Escaping of text for JSON string literals, for the JSON lines the programs print.
#pragma once

#include <string>
#include <string_view>

namespace traverse {

// `s` escaped for use between double quotes in JSON (quotes, backslashes, control characters
// and non-ASCII bytes as \uXXXX, so a line stays valid ASCII JSON whatever bytes came in).
std::string json_escape(std::string_view s);

}  // namespace traverse
