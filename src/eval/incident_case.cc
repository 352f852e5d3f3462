// The incident judge's records and words: a case's recorded ticks, and the names and the one-line
// description of its results (incident_judge.h).
#include "frenetic/eval/incident_judge.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>

namespace frenetic::sim {

void IncidentCase::AddTick(const RecordedEgo& e, std::span<const RecordedCar> tick_cars) {
  ego.push_back(e);
  cars.insert(cars.end(), tick_cars.begin(), tick_cars.end());
  car_begin.push_back(static_cast<int>(cars.size()));
}

void IncidentCase::AddMonitor(std::int64_t tick, const IncidentMonitor& monitor) {
  monitor_ticks.push_back(tick);
  monitors.push_back(monitor);
  monitors.back().ClearLog();
}

std::span<const RecordedCar> IncidentCase::CarsAt(std::int64_t tick) const {
  const std::int64_t i = tick - first_tick;
  if (i < 0 || i + 1 >= static_cast<std::int64_t>(car_begin.size())) return {};
  return {cars.data() + car_begin[i], cars.data() + car_begin[i + 1]};
}

const char* ToString(StartResult result) {
  switch (result) {
    case StartResult::kAvoidable:
      return "avoidable";
    case StartResult::kUnavoidable:
      return "unavoidable";
    case StartResult::kUndecided:
      return "undecided";
    case StartResult::kInIncident:
      return "in_incident";
  }
  return "?";
}

const char* ToString(Verdict verdict) {
  switch (verdict) {
    case Verdict::kAvoidable:
      return "avoidable";
    case Verdict::kUnavoidable:
      return "unavoidable";
    case Verdict::kUndecided:
      return "undecided";
    case Verdict::kNotJudged:
      return "not_judged";
  }
  return "?";
}

std::string Describe(const IncidentJudgement& j) {
  switch (j.verdict) {
    case Verdict::kAvoidable:
      return fmt::format("avoidable from t = {:.2f} s, last chance {:.2f} s ({:.2f} s before)",
                         j.avoidable_from, j.last_chance, j.incident_t - j.last_chance);
    case Verdict::kUnavoidable: {
      double first = j.incident_t;
      for (const StartJudgement& s : j.starts) {
        if (s.result != StartResult::kInIncident) first = std::min(first, s.t);
      }
      return fmt::format("unavoidable from every start since t = {:.2f} s: the traffic's", first);
    }
    case Verdict::kUndecided: {
      int out = 0;
      for (const StartJudgement& s : j.starts) out += s.result == StartResult::kUndecided;
      return fmt::format("undecided: no escape found, {} of {} searches ran out of budget", out,
                         j.starts.size());
    }
    case Verdict::kNotJudged:
      break;
  }
  return "not judged";
}

}  // namespace frenetic::sim
