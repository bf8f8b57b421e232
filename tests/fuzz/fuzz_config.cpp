// Fuzz target: YAML config files read into config structs (every kind of member: scalars,
// lists, nested structs, lists of structs), the optimiser's, the monitor's, a deployment and the
// input section. Anything wrong must come out as a ConfigError naming the file; any other
// exception is a finding.
#include <cstdint>
#include <string>
#include <vector>

#include "config.hpp"
#include "deployment.hpp"
#include "input_config.hpp"
#include "monitor_node.hpp"
#include "spa.hpp"

namespace {

struct Inner {
  double x_m = 0;
  std::vector<int> ids;
  template <class V>
  void visit(V& v) {
    v("x_m", x_m);
    v("ids", ids);
  }
};

struct Everything {
  bool flag = false;
  int count = 0;
  int64_t big = 0;
  double value = 0;
  std::string name;
  std::vector<double> values;
  std::vector<std::string> names;
  Inner inner;
  std::vector<Inner> inners;
  template <class V>
  void visit(V& v) {
    v("flag", flag);
    v("count", count);
    v("big", big);
    v("value", value);
    v("name", name);
    v("values", values);
    v("names", names);
    v("inner", inner);
    v("inners", inners);
  }
};

template <class Config>
void load(const std::string& text) {
  Config c;
  try {
    traverse::load_config_text(text, "fuzz.yaml", c);
  } catch (const traverse::ConfigError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  load<Everything>(text);
  load<traverse::backend::SpaConfig>(text);
  load<traverse::MonitorConfig>(text);
  load<traverse::launch::Deployment>(text);
  load<traverse::InputConfig>(text);
  return 0;
}
