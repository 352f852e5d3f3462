// The registry of cost terms by name. Terms register at static-initialisation time with one
// line at the end of their file:  FRENETIC_REGISTER_COST(jerk, JerkCost);
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/cost/cost_term.h"
#include "frenetic/status.h"

namespace frenetic::cost {

using CostFactory = std::unique_ptr<CostTerm> (*)();

class CostRegistry {
 public:
  static CostRegistry& Global();
  // Adds a term; a duplicate name is a program error (aborts with a message).
  bool Register(std::string_view name, CostFactory factory);
  // Registered names, sorted.
  std::vector<std::string> Names() const;
  bool Contains(std::string_view name) const;
  // A new instance of the named term, or an error naming the unknown term.
  StatusOr<std::unique_ptr<CostTerm>> Make(std::string_view name) const;

 private:
  std::vector<std::pair<std::string, CostFactory>> entries_;
};

}  // namespace frenetic::cost

#define FRENETIC_REGISTER_COST(name, Class)                                       \
  [[maybe_unused]] static const bool frenetic_cost_registered_##name =            \
      ::frenetic::cost::CostRegistry::Global().Register(                          \
          #name, []() -> std::unique_ptr<::frenetic::cost::CostTerm> {            \
            return std::make_unique<Class>();                                     \
          })
