#include "frenetic/cost/cost_registry.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace frenetic::cost {

CostRegistry& CostRegistry::Global() {
  // Function-local static: safe to use from other translation units' static initialisers.
  static CostRegistry* registry = new CostRegistry();
  return *registry;
}

bool CostRegistry::Register(std::string_view name, CostFactory factory) {
  if (Contains(name) || factory == nullptr) {
    std::fprintf(stderr, "cost term '%.*s' registered twice or without factory\n",
                 static_cast<int>(name.size()), name.data());
    std::abort();
  }
  entries_.emplace_back(std::string(name), factory);
  return true;
}

std::vector<std::string> CostRegistry::Names() const {
  std::vector<std::string> names;
  for (const auto& e : entries_) names.push_back(e.first);
  std::sort(names.begin(), names.end());
  return names;
}

bool CostRegistry::Contains(std::string_view name) const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const auto& e) { return e.first == name; });
}

StatusOr<std::unique_ptr<CostTerm>> CostRegistry::Make(std::string_view name) const {
  for (const auto& e : entries_) {
    if (e.first == name) return e.second();
  }
  return Status::Error("unknown cost term '" + std::string(name) + "'");
}

}  // namespace frenetic::cost
