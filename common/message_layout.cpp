#include "message_layout.hpp"

#include <algorithm>
#include <map>
#include <sstream>
#include <stdexcept>

namespace traverse {
namespace {

struct Primitive {
  const char* name;
  int bytes;
  bool integer;
};
constexpr Primitive kPrimitives[] = {
    {"int8_t", 1, true}, {"int16_t", 2, true},  {"int32_t", 4, true}, {"int64_t", 8, true},
    {"byte", 1, false},  {"boolean", 1, false}, {"float", 4, false},  {"double", 8, false},
};

const Primitive* primitive(const std::string& name) {
  for (const Primitive& p : kPrimitives) {
    if (name == p.name) return &p;
  }
  return nullptr;
}

[[noreturn]] void parse_error(int line, const std::string& what) {
  throw std::runtime_error("lcm-gen -d output, line " + std::to_string(line) + ": " + what);
}

// The fewest bytes a value of `f` takes: constant dimensions multiply, a variable one may be 0.
int64_t min_bytes_of(const FieldLayout& f) {
  int64_t count = 1;
  for (const FieldLayout::Dim& d : f.dims) count *= d.var_field < 0 ? d.size : 0;
  switch (f.kind) {
    case FieldLayout::Kind::kPrimitive:
      return count * f.primitive_bytes;
    case FieldLayout::Kind::kString:
      return count * 5;  // int32 length and at least the NUL
    case FieldLayout::Kind::kStruct:
      return count * f.type->min_bytes;
  }
  return 0;
}

// Reads the big-endian signed integer of `bytes` bytes at p.
int64_t read_int(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  const int shift = 64 - 8 * bytes;
  return shift == 0 ? static_cast<int64_t>(v) : static_cast<int64_t>(v << shift) >> shift;
}

class Walker {
 public:
  Walker(const uint8_t* data, std::size_t size, const std::vector<ArrayLimit>& limits)
      : data_(data), size_(size), limits_(limits) {}

  bool walk_struct(const StructLayout& s, int depth) {
    if (depth > 32) return fail(WalkResult::Outcome::kMalformed, s.name + " nests too deep");
    std::vector<int64_t> values(s.fields.size(), 0);  // integer fields, for variable sizes
    for (std::size_t k = 0; k < s.fields.size(); ++k) {
      const FieldLayout& f = s.fields[k];
      int64_t count = 1;
      for (const FieldLayout::Dim& d : f.dims) {
        const int64_t n = d.var_field < 0 ? d.size : values[d.var_field];
        if (n < 0) {
          return fail(WalkResult::Outcome::kMalformed,
                      s.name + "." + f.name + " claims " + std::to_string(n) + " elements");
        }
        // Every partial product is an allocation of the decoder (nested vectors): each must be
        // held by the bytes left, at one byte per element at least.
        if (n > 0 && count > static_cast<int64_t>(left()) / n) {
          return fail(WalkResult::Outcome::kMalformed, s.name + "." + f.name + " claims " +
                                                           std::to_string(count) + " x " +
                                                           std::to_string(n) + " elements, " +
                                                           std::to_string(left()) + " bytes left");
        }
        count *= n;
      }
      if (!f.dims.empty() && !within_limits(s, f, count)) return false;
      if (f.kind == FieldLayout::Kind::kPrimitive) {
        const auto bytes = static_cast<uint64_t>(count) * static_cast<uint64_t>(f.primitive_bytes);
        if (bytes > left()) {
          return fail(WalkResult::Outcome::kMalformed, s.name + "." + f.name + " claims " +
                                                           std::to_string(count) + " elements (" +
                                                           std::to_string(bytes) + " bytes), " +
                                                           std::to_string(left()) + " bytes left");
        }
        if (f.dims.empty() && f.is_integer) values[k] = read_int(data_ + pos_, f.primitive_bytes);
        pos_ += bytes;
        continue;
      }
      const int64_t element_bytes =
          f.kind == FieldLayout::Kind::kString ? 5 : std::max<int64_t>(f.type->min_bytes, 0);
      if (element_bytes > 0 && count > static_cast<int64_t>(left()) / element_bytes) {
        return fail(WalkResult::Outcome::kMalformed, s.name + "." + f.name + " claims " +
                                                         std::to_string(count) + " elements, " +
                                                         std::to_string(left()) + " bytes left");
      }
      for (int64_t i = 0; i < count; ++i) {
        if (f.kind == FieldLayout::Kind::kString ? !walk_string(s, f)
                                                 : !walk_struct(*f.type, depth + 1)) {
          return false;
        }
      }
    }
    return true;
  }

  std::size_t pos() const { return pos_; }
  WalkResult result;

 private:
  std::size_t left() const { return size_ - pos_; }

  bool walk_string(const StructLayout& s, const FieldLayout& f) {
    if (left() < 4) return fail(WalkResult::Outcome::kMalformed, s.name + "." + f.name + " cut");
    const int64_t n = read_int(data_ + pos_, 4);
    pos_ += 4;
    // The length counts the terminating NUL: 0 or less makes the decoder throw.
    if (n < 1 || static_cast<uint64_t>(n) > left()) {
      return fail(WalkResult::Outcome::kMalformed, s.name + "." + f.name + " claims a string of " +
                                                       std::to_string(n) + " bytes, " +
                                                       std::to_string(left()) + " bytes left");
    }
    pos_ += static_cast<std::size_t>(n);
    return true;
  }

  bool within_limits(const StructLayout& s, const FieldLayout& f, int64_t count) {
    for (const ArrayLimit& l : limits_) {
      if (count > l.max_elements && l.field == f.name && l.type == s.name) {
        return fail(WalkResult::Outcome::kOverLimit,
                    s.name + "." + f.name + " has " + std::to_string(count) +
                        " elements, more than the limit of " + std::to_string(l.max_elements));
      }
    }
    return true;
  }

  bool fail(WalkResult::Outcome outcome, std::string problem) {
    result.outcome = outcome;
    result.problem = std::move(problem);
    return false;
  }

  const uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  const std::vector<ArrayLimit>& limits_;
};

}  // namespace

LayoutSet LayoutSet::parse(std::string_view text) {
  LayoutSet set;
  std::map<std::string, StructLayout*> by_name;
  std::istringstream in{std::string(text)};
  std::string raw;
  StructLayout* current = nullptr;
  for (int line = 1; std::getline(in, raw); ++line) {
    std::istringstream ls(raw);
    std::string first;
    if (!(ls >> first)) continue;
    if (first == "struct") {
      auto s = std::make_unique<StructLayout>();
      if (!(ls >> s->name)) parse_error(line, "struct without a name");
      current = s.get();
      by_name[s->name] = current;
      set.types_.push_back(std::move(s));
      continue;
    }
    if (!current) parse_error(line, "field outside a struct");
    FieldLayout f;
    f.type_name = first;
    if (!(ls >> f.name)) parse_error(line, "field without a name");
    // Dimensions: "[ (const) 3 ]" or "[ (var) n_ranges ]", one bracket per dimension.
    for (std::string open, kind, size, close; ls >> open;) {
      if (open != "[" || !(ls >> kind >> size >> close) || close != "]") {
        parse_error(line, "cannot read the dimensions of " + f.name);
      }
      FieldLayout::Dim d;
      if (kind == "(const)") {
        d.size = std::stoll(size);
      } else if (kind == "(var)") {
        for (std::size_t k = 0; k < current->fields.size(); ++k) {
          const FieldLayout& g = current->fields[k];
          if (g.name == size && g.kind == FieldLayout::Kind::kPrimitive && g.is_integer &&
              g.dims.empty()) {
            d.var_field = static_cast<int>(k);
          }
        }
        if (d.var_field < 0) parse_error(line, "size " + size + " is no earlier integer field");
      } else {
        parse_error(line, "unknown dimension kind " + kind);
      }
      f.dims.push_back(d);
    }
    if (const Primitive* p = primitive(f.type_name)) {
      f.kind = FieldLayout::Kind::kPrimitive;
      f.primitive_bytes = p->bytes;
      f.is_integer = p->integer;
    } else if (f.type_name == "string") {
      f.kind = FieldLayout::Kind::kString;
    } else {
      f.kind = FieldLayout::Kind::kStruct;
    }
    current->fields.push_back(std::move(f));
  }
  // Struct-typed fields, resolved once every type is known.
  for (auto& s : set.types_) {
    for (FieldLayout& f : s->fields) {
      if (f.kind != FieldLayout::Kind::kStruct) continue;
      const auto it = by_name.find(f.type_name);
      if (it == by_name.end()) {
        throw std::runtime_error("lcm-gen -d output: " + s->name + "." + f.name +
                                 " has the unknown type " + f.type_name);
      }
      f.type = it->second;
    }
  }
  // Minimum sizes, innermost types first: repeat until nothing changes (types cannot nest
  // themselves, so this ends within as many rounds as there are types).
  for (std::size_t round = 0; round <= set.types_.size(); ++round) {
    bool changed = false;
    for (auto& s : set.types_) {
      int64_t bytes = 0;
      for (const FieldLayout& f : s->fields) bytes += min_bytes_of(f);
      changed = changed || bytes != s->min_bytes;
      s->min_bytes = bytes;
    }
    if (!changed) break;
  }
  return set;
}

const StructLayout* LayoutSet::find(std::string_view type_name) const {
  for (const auto& s : types_) {
    if (s->name == type_name) return s.get();
  }
  return nullptr;
}

WalkResult walk_message(const StructLayout& layout, const uint8_t* data, std::size_t size,
                        const std::vector<ArrayLimit>& limits) {
  if (size < 8) return {WalkResult::Outcome::kMalformed, "shorter than a fingerprint"};
  Walker w(data + 8, size - 8, limits);
  if (!w.walk_struct(layout, 0)) return w.result;
  if (w.pos() != size - 8) {
    return {WalkResult::Outcome::kMalformed,
            std::to_string(size - 8 - w.pos()) + " bytes after the end of the " + layout.name};
  }
  return {WalkResult::Outcome::kOk, ""};
}

}  // namespace traverse
