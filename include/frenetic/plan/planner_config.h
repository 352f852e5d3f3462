// The planner's configuration (config/planner.yaml): limits, grid, budgets, and the weighted cost
// terms in evaluation order. Every value is validated: unknown sections, keys and cost terms are
// errors naming them and the file; every registered cost term needs a weight.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "frenetic/cost/cost_set.h"
#include "frenetic/status.h"

namespace frenetic::plan {

class PlannerConfig {
 public:
  // Reads and validates a YAML file; errors name the file and the key.
  static StatusOr<PlannerConfig> Load(const std::string& path);
  // Parses YAML text; `source` (a file name or label) is named in errors.
  static StatusOr<PlannerConfig> Parse(std::string_view yaml, std::string_view source);
  static std::string DefaultPath();  // FRENETIC_SOURCE_DIR "/config/planner.yaml"
  static StatusOr<PlannerConfig> LoadDefault();

  // Changes some values: YAML laid out as planner.yaml (sections of keys, `costs` of terms with
  // weight and parameters), any subset of it. Errors name `source` and the key (unknown, not a
  // number, out of range); on an error nothing is changed.
  Status Overlay(std::string_view yaml, std::string_view source);
  Status OverlayFile(const std::string& path);

  // Dotted keys: "section.key" (e.g. "limits.max_speed_mph"), "weights.<term>" and
  // "costs.<term>.<param>". Set rejects unknown keys and values outside the declared range.
  Status Set(std::string_view key, double value);
  StatusOr<double> Get(std::string_view key) const;

  // Declared tunable parameters (OMPL-style): every cost weight and numeric planner parameter,
  // with a sensible [lo, hi] range and whether a log scale suits it.
  struct Param {
    std::string key;
    double value, lo, hi;
    bool log_scale;
  };
  std::vector<Param> Params() const;
  std::string ToYaml() const;  // round-trips through Parse
  double budget_ms() const;    // per-cycle deadline (config key budget_ms)
  // Switches the wall-clock deadlines (budget_ms, refine.budget_ms) off: no deadline cuts a
  // cycle short however loaded the machine is, so the planner's answers depend on its inputs
  // only (refinement stays on, bounded by refine.max_iterations). For headless drives, tuning
  // and fidelity runs, whose latency is counted in ticks, not measured. A later Set() of either
  // key switches that deadline back on at the value set.
  void PinDeadlines();
  bool budget_pinned() const { return budget_pinned_; }
  bool refine_budget_pinned() const { return refine_budget_pinned_; }

  // The value of a declared key; aborts on an undeclared one (a program error).
  double value(std::string_view key) const;
  int int_value(std::string_view key) const;  // rounded
  const std::string& refine_algorithm() const { return refine_algorithm_; }
  // The cost terms in config (evaluation) order with weights and parameters.
  std::vector<cost::CostTermConfig> cost_terms() const;
  const std::string& source() const { return source_; }

  // The built-in defaults with every registered cost term at weight 1 (for tests and tools).
  static PlannerConfig Defaults();

 private:
  Status Validate() const;
  Param* Find(std::string_view key);
  const Param* Find(std::string_view key) const;

  std::vector<Param> params_;              // planner parameters, then weights and term params
  std::vector<std::string> cost_order_;    // term names in config order
  std::string refine_algorithm_ = "LN_COBYLA";
  std::string source_ = "<defaults>";
  bool budget_pinned_ = false;
  bool refine_budget_pinned_ = false;
};

}  // namespace frenetic::plan
