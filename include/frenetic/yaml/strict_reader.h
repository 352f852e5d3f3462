// The one strict reader of frenetic's YAML files (planner configuration, scenarios, tuning suites):
// unknown and repeated keys are errors, values are typed and range-checked, and every error is
// one line naming the file and the dotted key (STYLE.md, Code 8). yaml-cpp throws on bad input;
// its exceptions are caught here, at the edge, and become a Status.
//
// Messages, all prefixed with "<source>: ":
//   YAML error at line N: <what yaml-cpp says>
//   expected a mapping at the top level
//   'traffic.cut_in' must be a mapping
//   unknown key 'traffic.cut_in.rte'
//   key 'seed' appears twice
//   'traffic.cars' must be an integer, got 'many'   (a number, a boolean, a string)
//   'grid.speeds' = 1000 outside [8, 64]
//   'traffic.batch' must be a pair of numbers [min, max]
//   'scenarios' must be a list
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/status.h"

namespace frenetic::yaml {

// Parses YAML text; a syntax error names `source` and the line.
StatusOr<YAML::Node> Load(std::string_view text, std::string_view source);

// Reads the keys of one YAML map, remembering which were asked for, so that Finish() can report
// the others. An absent or null node reads as an empty map. The readers of one document share
// its first error: once there is one, every read does nothing, and status() keeps that error.
class MapReader {
 public:
  // The document's top level.
  MapReader(const YAML::Node& root, std::string source);

  bool ok() const { return state_->status.ok(); }
  const Status& status() const { return state_->status; }

  // The map at `key` (marked as known); its keys are named "<prefix><key>.<name>".
  MapReader Sub(std::string_view key);

  // Typed reads: an absent key leaves `*out` unchanged and returns false. A present key of the
  // wrong type, or a non-finite number, is an error.
  bool Read(std::string_view key, bool* out);
  bool Read(std::string_view key, int* out);
  bool Read(std::string_view key, std::uint64_t* out);
  bool Read(std::string_view key, double* out);
  bool Read(std::string_view key, std::string* out);
  // A number within [lo, hi].
  bool Read(std::string_view key, double* out, double lo, double hi);
  // A [min, max] pair of numbers (of integers).
  bool ReadPair(std::string_view key, double* lo, double* hi);
  bool ReadPair(std::string_view key, int* lo, int* hi);
  // A list of values of one type (elements named "key[i]").
  bool ReadList(std::string_view key, std::vector<std::string>* out);
  bool ReadList(std::string_view key, std::vector<std::uint64_t>* out);

  // Whether the map has `key` (does not mark it known).
  bool Has(std::string_view key) const;
  // The node at `key`, for shapes the typed reads do not cover; marks it known.
  YAML::Node Child(std::string_view key);
  void MarkKnown(std::string_view key) { known_.emplace(key); }
  // The map's keys in document order.
  const std::vector<std::string>& Keys() const { return keys_; }
  // The dotted name of `key` in this map, as messages name it.
  std::string Name(std::string_view key) const { return prefix_ + std::string(key); }

  // Records "<source>: '<name>' <what>" unless there is an error already.
  void Fail(std::string_view name, std::string_view what);
  // Records "<source>: <message>" unless there is an error already.
  void Error(std::string_view message);
  // Reports the first key that was not read or marked known.
  void Finish();

 private:
  struct State {
    std::string source;
    Status status;
  };
  MapReader(const YAML::Node& node, std::string prefix, std::shared_ptr<State> state);
  // The scalar at `key`, or an undefined node when absent (or after an error); marks it known.
  YAML::Node Scalar(std::string_view key, const char* type);
  template <typename T>
  bool ReadScalar(std::string_view key, const char* type, T* out);
  template <typename T>
  bool ReadListOf(std::string_view key, const char* type, std::vector<T>* out);

  YAML::Node node_;  // a map, or undefined (absent, null or not a map)
  std::string prefix_;
  std::shared_ptr<State> state_;
  std::vector<std::string> keys_;
  std::set<std::string, std::less<>> known_;
};

}  // namespace frenetic::yaml
