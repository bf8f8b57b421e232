// The JSON every program writes (summary lines, monitor.json, processes.json, report files), on
// nlohmann-json: keys stay in the order written (ordered_json), so a person reading a line finds
// the headline figures first and the scripts' parsers find the same keys as always.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace traverse {

using Json = nlohmann::ordered_json;

// A figure as printed with `decimals` digits after the point (printf "%.*f"), so a summary line
// carries what was measured and no binary noise; null when absent or not finite.
Json json_fixed(std::optional<double> v, int decimals);
// The same with `digits` significant digits (printf "%.*g").
Json json_significant(std::optional<double> v, int digits);

// One line of ASCII JSON: characters beyond ASCII escaped as \uXXXX, bytes that are not UTF-8
// (a log's channel name, a file name) replaced by U+FFFD instead of failing the dump.
std::string json_line(const Json& j);

}  // namespace traverse
