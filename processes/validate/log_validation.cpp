#include "log_validation.hpp"

namespace traverse::validate {

LogValidation validate_log(const std::string& path) {
  LogValidation v;
  v.log = path;
  LogReader reader(path);
  StreamAnalyzer analyzer;
  while (auto ev = reader.next()) {
    analyzer.add(ev->channel, ev->utime, ev->data.data(), ev->data.size());
  }
  v.bytes = reader.file_size();
  v.events = analyzer.events();
  v.channels = analyzer.summary();
  v.damage = reader.damage();
  for (const LogDamage& d : v.damage) {
    v.problems.push_back("damage at byte " + std::to_string(d.offset) + ": " + d.what);
  }
  for (auto& p : channel_problems(v.channels)) v.problems.push_back(std::move(p));
  if (v.events == 0) v.problems.push_back("no readable events");
  v.ok = v.problems.empty();
  return v;
}

std::string to_json(const LogValidation& v) {
  Json j;
  j["log"] = v.log;
  j["bytes"] = v.bytes;
  j["events"] = v.events;
  j["channels"] = channels_json(v.channels);
  j["damage"] = Json::array();
  for (const LogDamage& d : v.damage) {
    j["damage"].push_back(
        {{"offset", d.offset}, {"what", d.what}, {"skipped_bytes", d.skipped_bytes}});
  }
  j["problems"] = v.problems;
  j["ok"] = v.ok;
  return json_line(j);
}

std::string to_text(const LogValidation& v) {
  std::string out = v.log + ": " + std::to_string(v.bytes) + " bytes, " + std::to_string(v.events) +
                    " events, " + std::to_string(v.channels.size()) + " channels\n\n";
  out += channel_table(v.channels);
  if (!v.damage.empty()) out += "\n";
  for (const LogDamage& d : v.damage) {
    out += "damage at byte " + std::to_string(d.offset) + ": " + d.what + " (" +
           std::to_string(d.skipped_bytes) + " bytes skipped)\n";
  }
  out += "\n";
  for (const auto& p : v.problems) out += "problem: " + p + "\n";
  out += v.ok ? "log is clean\n" : "log has problems\n";
  return out;
}

}  // namespace traverse::validate
