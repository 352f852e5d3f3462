#include "frenetic/yaml/strict_reader.h"

#include <cmath>
#include <sstream>
#include <utility>

namespace frenetic::yaml {
namespace {

// 17 significant digits: a value and a bound that differ print differently.
std::string Fmt(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

// A key as text ("?" for a key that is not a scalar, such as a list used as a key).
std::string KeyText(const YAML::Node& key) { return key.IsScalar() ? key.Scalar() : "?"; }

}  // namespace

StatusOr<YAML::Node> Load(std::string_view text, std::string_view source) {
  try {
    return YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    return Status::Error(std::string(source) + ": YAML error at line " +
                         std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

MapReader::MapReader(const YAML::Node& root, std::string source)
    : MapReader(root, "", std::make_shared<State>(State{std::move(source), Status::Ok()})) {}

MapReader::MapReader(const YAML::Node& node, std::string prefix, std::shared_ptr<State> state)
    : prefix_(std::move(prefix)), state_(std::move(state)) {
  if (!node.IsDefined() || node.IsNull()) return;
  if (!node.IsMap()) {
    if (prefix_.empty()) {
      Error("expected a mapping at the top level");
    } else {
      Fail(prefix_.substr(0, prefix_.size() - 1), "must be a mapping");
    }
    return;
  }
  node_ = node;
  std::set<std::string, std::less<>> seen;
  for (const auto& kv : node_) {
    std::string key = KeyText(kv.first);
    if (!seen.insert(key).second) Error("key '" + Name(key) + "' appears twice");
    keys_.push_back(std::move(key));
  }
}

void MapReader::Error(std::string_view message) {
  if (state_->status.ok()) {
    state_->status = Status::Error(state_->source + ": " + std::string(message));
  }
}

void MapReader::Fail(std::string_view name, std::string_view what) {
  // Appended, not "'" + std::string(name): GCC 12 warns falsely (-Wrestrict) on the latter.
  Error(std::string("'").append(name).append("' ").append(what));
}

bool MapReader::Has(std::string_view key) const {
  if (!node_.IsDefined()) return false;
  const YAML::Node& n = node_;
  return n[std::string(key)].IsDefined();
}

YAML::Node MapReader::Child(std::string_view key) {
  MarkKnown(key);
  if (!node_.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
  const YAML::Node& n = node_;
  return n[std::string(key)];
}

MapReader MapReader::Sub(std::string_view key) {
  const YAML::Node child = Child(key);
  return MapReader(ok() ? child : YAML::Node(YAML::NodeType::Undefined), Name(key) + ".", state_);
}

YAML::Node MapReader::Scalar(std::string_view key, const char* type) {
  const YAML::Node v = Child(key);
  if (!ok() || !v.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
  if (!v.IsScalar()) {
    Fail(Name(key), std::string("must be ") + type);
    return YAML::Node(YAML::NodeType::Undefined);
  }
  return v;
}

template <typename T>
bool MapReader::ReadScalar(std::string_view key, const char* type, T* out) {
  const YAML::Node v = Scalar(key, type);
  if (!v.IsDefined()) return false;
  T value{};
  bool good = true;
  try {
    value = v.as<T>();
  } catch (const YAML::Exception&) {
    good = false;
  }
  if constexpr (std::is_floating_point_v<T>) good = good && std::isfinite(value);
  if (!good) {
    Fail(Name(key), std::string("must be ") + type + ", got '" + v.Scalar() + "'");
    return false;
  }
  *out = value;
  return true;
}

bool MapReader::Read(std::string_view key, bool* out) { return ReadScalar(key, "a boolean", out); }
bool MapReader::Read(std::string_view key, int* out) { return ReadScalar(key, "an integer", out); }
bool MapReader::Read(std::string_view key, std::uint64_t* out) {
  return ReadScalar(key, "a non-negative integer", out);
}
bool MapReader::Read(std::string_view key, double* out) { return ReadScalar(key, "a number", out); }
bool MapReader::Read(std::string_view key, std::string* out) {
  return ReadScalar(key, "a string", out);
}

bool MapReader::Read(std::string_view key, double* out, double lo, double hi) {
  double v = 0;
  if (!Read(key, &v)) return false;
  if (v < lo || v > hi) {
    Fail(Name(key), "= " + Fmt(v) + " outside [" + Fmt(lo) + ", " + Fmt(hi) + "]");
    return false;
  }
  *out = v;
  return true;
}

bool MapReader::ReadPair(std::string_view key, double* lo, double* hi) {
  const YAML::Node v = Child(key);
  if (!ok() || !v.IsDefined()) return false;
  bool good = v.IsSequence() && v.size() == 2;
  double a = 0, b = 0;
  try {
    if (good) {
      a = v[0].as<double>();
      b = v[1].as<double>();
    }
  } catch (const YAML::Exception&) {
    good = false;
  }
  if (!good || !std::isfinite(a) || !std::isfinite(b)) {
    Fail(Name(key), "must be a pair of numbers [min, max]");
    return false;
  }
  *lo = a;
  *hi = b;
  return true;
}

bool MapReader::ReadPair(std::string_view key, int* lo, int* hi) {
  double a = *lo, b = *hi;
  if (!ReadPair(key, &a, &b)) return false;
  if (a != std::floor(a) || b != std::floor(b) || std::abs(a) > 1e9 || std::abs(b) > 1e9) {
    Fail(Name(key), "must be a pair of integers [min, max]");
    return false;
  }
  *lo = static_cast<int>(a);
  *hi = static_cast<int>(b);
  return true;
}

template <typename T>
bool MapReader::ReadListOf(std::string_view key, const char* type, std::vector<T>* out) {
  const YAML::Node v = Child(key);
  if (!ok() || !v.IsDefined()) return false;
  if (!v.IsSequence()) {
    Fail(Name(key), "must be a list");
    return false;
  }
  std::vector<T> values;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string name = Name(key) + "[" + std::to_string(i) + "]";
    bool good = v[i].IsScalar();
    T value{};
    try {
      if (good) value = v[i].as<T>();
    } catch (const YAML::Exception&) {
      good = false;
    }
    if (!good) {
      Fail(name, std::string("must be ") + type);
      return false;
    }
    values.push_back(std::move(value));
  }
  *out = std::move(values);
  return true;
}

bool MapReader::ReadList(std::string_view key, std::vector<std::string>* out) {
  return ReadListOf(key, "a string", out);
}
bool MapReader::ReadList(std::string_view key, std::vector<std::uint64_t>* out) {
  return ReadListOf(key, "a non-negative integer", out);
}

void MapReader::Finish() {
  if (!ok()) return;
  for (const std::string& key : keys_) {
    if (!known_.count(key)) return Error("unknown key '" + Name(key) + "'");
  }
}

}  // namespace frenetic::yaml
