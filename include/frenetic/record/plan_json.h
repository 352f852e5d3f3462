// The planner's side of a record's exchange line (schema.h), written in one place for every
// kind of run: the "plan" object and the header's "config".
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "frenetic/plan/planner.h"

namespace frenetic::record {

// An exchange line's "plan" object: the status ("ok", "fallback", ...), the counts, rejections
// by reason and the winner's costs of `summary`, and the traced `candidates` (best first; their
// coordinates at 0.1 m, as `frenetic report` draws them: their digits beyond that were most of a
// record). Every time (plan_ms, the summary's stage times) is multiplied by `time_scale`: 0
// with timing off. Non-finite numbers are written as null.
nlohmann::json PlanJson(plan::PlanStatus status, const plan::PlanSummary& summary, double plan_ms,
                        double time_scale, const std::vector<plan::CandidateTrace>& candidates);

// The planner YAML as JSON (numbers, booleans, strings, maps, lists); the text itself on error.
nlohmann::json YamlToJson(const std::string& yaml_text);

}  // namespace frenetic::record
