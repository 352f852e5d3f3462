// An immutable, weighted set of cost terms in config order: the snapshot the planner scores
// with. Built once from validated configuration; shared read-only (weights can change between
// cycles by building a new set).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "frenetic/cost/cost_term.h"
#include "frenetic/status.h"

namespace frenetic::cost {

// One term as configured: its registered name, weight (>= 0) and parameter values by key
// (absent keys take the term's defaults).
struct CostTermConfig {
  std::string name;
  double weight = 0;
  std::vector<std::pair<std::string, double>> params;
};

class CostSet {
 public:
  // The values of the LaneOnly() terms per target lane, kept by CostSet::LowerBound for the
  // context it was filled under: Clear() it whenever the context changes.
  class LaneMemo {
   public:
    void Clear() {
      for (auto& row : known_) row.fill(0);
    }

   private:
    friend class CostSet;
    static constexpr int kMaxTerms = 16;
    std::array<std::array<char, kMaxLanes>, kMaxTerms> known_{};
    std::array<std::array<double, kMaxLanes>, kMaxTerms> value_{};
  };

  // Errors name the unknown term, the unknown parameter key or the bad value.
  static StatusOr<std::shared_ptr<const CostSet>> Build(const std::vector<CostTermConfig>& terms);

  int size() const { return static_cast<int>(terms_.size()); }
  const std::string& name(int i) const { return names_[i]; }
  double weight(int i) const { return weights_[i]; }
  const CostTerm& term(int i) const { return *terms_[i]; }

  // Weighted sum over the terms in config order. When per_term is not null it receives the
  // unweighted value of each term (size() entries). Does not allocate.
  double Evaluate(const CostContext& ctx, const CostInput& in, double* per_term = nullptr) const;
  // The same weighted sum with every Expensive() term taken as its CostTerm::LowerBound (0 for
  // most): never more than Evaluate(ctx, in) (terms and weights are >= 0, the bounds are not
  // above the values, and rounded addition and multiplication are monotone), so a
  // candidate whose bound is above another's exact total cannot rank before it. NaN when a
  // cheap term is NaN (Evaluate is then NaN too). Does not allocate.
  // When cheap is not null it receives the unweighted value of each term that is not
  // Expensive() (the LowerBound of those that are; size() entries).
  // With memo (not null), a LaneOnly() term is evaluated once per target lane while the memo
  // is not cleared: the same values.
  double LowerBound(const CostContext& ctx, const CostInput& in, double* cheap = nullptr,
                    LaneMemo* memo = nullptr) const;
  // LowerBound's sum with the Sampled() terms taken as 0, and the Expensive() ones as 0 in place
  // of their LowerBound: never more than LowerBound(ctx, in), by the same argument. cheap (not
  // null) receives the values of the terms it evaluates and 0 for the others; memo as
  // LowerBound's. Does not allocate.
  double CoarseLowerBound(const CostContext& ctx, const CostInput& in, double* cheap,
                          LaneMemo* memo = nullptr) const;
  // Completes a CoarseLowerBound of the same input: evaluates the Sampled() terms that are not
  // Expensive(), and the Expensive() terms' LowerBound, into cheap and returns LowerBound(ctx,
  // in) from cheap's values, the same sum term for term; cheap then holds what LowerBound would
  // have put there. Does not allocate.
  double CompleteLowerBound(const CostContext& ctx, const CostInput& in, double* cheap) const;
  // Evaluate(ctx, in) from the cheap terms' values LowerBound kept for the same input: only the
  // Expensive() terms are evaluated; the same sum, term for term. Does not allocate.
  double EvaluateWithCheap(const CostContext& ctx, const CostInput& in, const double* cheap) const;
  // The Expensive() terms' indices, in config order.
  const std::vector<int>& expensive_terms() const { return expensive_terms_; }
  // Evaluate's sum from each term's unweighted value in values[i], where an Expensive() term not
  // evaluated yet may hold a lower bound of its value instead (its LowerBound, as LowerBound and
  // CompleteLowerBound leave it in cheap): with those bounds and no Expensive() term evaluated it
  // is LowerBound, bit for bit; with every one evaluated it is Evaluate, bit for bit (the same
  // products, added in the same order); in between, between the two.
  double SumOf(const double* values) const;

 private:
  CostSet() = default;
  std::vector<std::string> names_;
  std::vector<double> weights_;
  std::vector<std::unique_ptr<CostTerm>> terms_;
  // LowerBound and CoarseLowerBound: the terms in `skip` are taken as 0, or with
  // expensive_bounds the Expensive() ones as their LowerBound.
  double BoundSkipping(const std::vector<char>& skip, bool expensive_bounds, const CostContext& ctx,
                       const CostInput& in, double* cheap, LaneMemo* memo) const;
  std::vector<char> expensive_, lane_only_;  // each term's Expensive() and LaneOnly()
  std::vector<int> expensive_terms_;         // the indices of the Expensive() ones
  std::vector<char> coarse_skip_;  // Expensive() or Sampled(): what CoarseLowerBound leaves out
};

}  // namespace frenetic::cost
