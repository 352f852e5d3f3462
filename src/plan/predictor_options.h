// The prediction.* keys every planner's predictor reads (the search planner adds its
// manoeuvre keys on top), so each planner reads them the same way.
#pragma once

#include "frenetic/plan/planner_config.h"
#include "plan/predictor.h"

namespace frenetic::plan {

inline PredictorOptions BasicPredictorOptions(const PlannerConfig& config) {
  PredictorOptions po;
  po.range = config.value("prediction.range");
  po.d_min = config.value("prediction.d_min");
  po.d_max = config.value("prediction.d_max");
  po.max_speed = config.value("prediction.max_speed");
  po.spike_ratio = config.value("prediction.spike_ratio");
  return po;
}

}  // namespace frenetic::plan
