#include "frenetic/cost/cost_set.h"

#include <cmath>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {

StatusOr<std::shared_ptr<const CostSet>> CostSet::Build(
    const std::vector<CostTermConfig>& terms) {
  std::shared_ptr<CostSet> set(new CostSet());
  for (const CostTermConfig& tc : terms) {
    for (const std::string& n : set->names_) {
      if (n == tc.name) return Status::Error("cost term '" + tc.name + "' listed twice");
    }
    auto made = CostRegistry::Global().Make(tc.name);
    if (!made.ok()) return made.status();
    if (!std::isfinite(tc.weight) || tc.weight < 0) {
      return Status::Error("weight of cost term '" + tc.name + "' must be finite and >= 0");
    }
    std::unique_ptr<CostTerm> term = std::move(made.value());
    const std::vector<CostParamSpec> specs = term->ParamSpecs();
    std::vector<double> values;
    for (const CostParamSpec& spec : specs) values.push_back(spec.default_value);
    for (const auto& [key, value] : tc.params) {
      bool found = false;
      for (size_t i = 0; i < specs.size(); ++i) {
        if (specs[i].key != key) continue;
        found = true;
        if (!std::isfinite(value) || value < specs[i].lo || value > specs[i].hi) {
          return Status::Error("parameter '" + tc.name + "." + key + "' = " +
                               std::to_string(value) + " outside [" +
                               std::to_string(specs[i].lo) + ", " + std::to_string(specs[i].hi) +
                               "]");
        }
        values[i] = value;
      }
      if (!found) {
        return Status::Error("unknown parameter '" + key + "' of cost term '" + tc.name + "'");
      }
    }
    term->Configure(values);
    set->names_.push_back(tc.name);
    set->weights_.push_back(tc.weight);
    if (term->Expensive()) set->expensive_terms_.push_back(static_cast<int>(set->terms_.size()));
    set->expensive_.push_back(term->Expensive());
    set->lane_only_.push_back(term->LaneOnly());
    set->coarse_skip_.push_back(term->Expensive() || term->Sampled());
    set->terms_.push_back(std::move(term));
  }
  return std::shared_ptr<const CostSet>(std::move(set));
}

double CostSet::Evaluate(const CostContext& ctx, const CostInput& in, double* per_term) const {
  double total = 0;
  const int n = size();
  for (int i = 0; i < n; ++i) {
    const double v = terms_[i]->Evaluate(ctx, in);
    if (per_term != nullptr) per_term[i] = v;
    total += weights_[i] * v;
  }
  return total;
}

double CostSet::LowerBound(const CostContext& ctx, const CostInput& in, double* cheap,
                           LaneMemo* memo) const {
  return BoundSkipping(expensive_, true, ctx, in, cheap, memo);
}

double CostSet::CoarseLowerBound(const CostContext& ctx, const CostInput& in, double* cheap,
                                 LaneMemo* memo) const {
  return BoundSkipping(coarse_skip_, false, ctx, in, cheap, memo);
}

double CostSet::BoundSkipping(const std::vector<char>& skip, bool expensive_bounds,
                              const CostContext& ctx, const CostInput& in, double* cheap,
                              LaneMemo* memo) const {
  // Evaluate's sum, term for term, with 0 in place of the skipped terms' values (an Expensive()
  // term's LowerBound with expensive_bounds).
  double total = 0;
  const int n = size();
  const int lane = in.target_lane;
  const bool memo_lane = memo != nullptr && lane >= 0 && lane < kMaxLanes;
  for (int i = 0; i < n; ++i) {
    double v = 0.0;
    if (skip[i]) {
      v = expensive_bounds && expensive_[i] ? terms_[i]->LowerBound(ctx, in) : 0.0;
    } else if (memo_lane && i < LaneMemo::kMaxTerms && lane_only_[i]) {
      if (!memo->known_[i][lane]) {
        memo->value_[i][lane] = terms_[i]->Evaluate(ctx, in);
        memo->known_[i][lane] = 1;
      }
      v = memo->value_[i][lane];
    } else {
      v = terms_[i]->Evaluate(ctx, in);
    }
    if (cheap != nullptr) cheap[i] = v;
    total += weights_[i] * v;
  }
  return total;
}

double CostSet::CompleteLowerBound(const CostContext& ctx, const CostInput& in,
                                   double* cheap) const {
  // LowerBound's sum from the values: the coarse bound's, the Sampled() terms' now, and the
  // Expensive() ones' LowerBound (CoarseLowerBound left them 0).
  double total = 0;
  const int n = size();
  for (int i = 0; i < n; ++i) {
    if (expensive_[i]) {
      cheap[i] = terms_[i]->LowerBound(ctx, in);
    } else if (coarse_skip_[i]) {
      cheap[i] = terms_[i]->Evaluate(ctx, in);
    }
    total += weights_[i] * cheap[i];
  }
  return total;
}

double CostSet::EvaluateWithCheap(const CostContext& ctx, const CostInput& in,
                                  const double* cheap) const {
  double total = 0;
  const int n = size();
  for (int i = 0; i < n; ++i) {
    const double v = expensive_[i] ? terms_[i]->Evaluate(ctx, in) : cheap[i];
    total += weights_[i] * v;
  }
  return total;
}

double CostSet::SumOf(const double* values) const {
  double total = 0;
  const int n = size();
  for (int i = 0; i < n; ++i) total += weights_[i] * values[i];
  return total;
}

}  // namespace frenetic::cost
