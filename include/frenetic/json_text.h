// JSON text for output (reports, --json, records, logs). A string that is not valid UTF-8 (a
// path, or a benchmark id read from a file, may hold any bytes) makes nlohmann::json::dump throw;
// here each invalid byte becomes U+FFFD instead, so that bad input never aborts an output.
#pragma once

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

namespace frenetic {

inline std::string JsonText(const nlohmann::json& j, int indent = -1) {
  return j.dump(indent, ' ', /*ensure_ascii=*/false, nlohmann::json::error_handler_t::replace);
}

// A number, or null when it is not finite (JSON has neither NaN nor infinity).
inline nlohmann::json FiniteOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

}  // namespace frenetic
