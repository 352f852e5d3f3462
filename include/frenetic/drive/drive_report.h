// What a drive produced: distance, time, speeds, incidents as the simulator counts them,
// following gaps and planning times; and the aggregate over many seeded episodes.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "frenetic/eval/incident_judge.h"
#include "frenetic/eval/oracle.h"
#include "frenetic/sim/drive_breakdown.h"
#include "frenetic/sim/incident_monitor.h"
#include "frenetic/units.h"

namespace frenetic::sim {

struct DriveReport {
  std::string scenario, planner, map, stop_reason;
  std::uint64_t seed = 0;
  double distance_m = 0;
  double sim_seconds = 0;
  int exchanges = 0;
  double avg_speed_mph = 0;
  double miles_to_first_incident = 0;  // the whole distance when there was none
  double best_miles_without_incident = 0;
  std::array<int, kIncidentKinds> incidents_by_kind{};
  int incidents = 0;
  double max_speed_mph = 0;
  double max_acc = 0;   // m/s^2, largest 0.2 s block total acceleration
  double max_jerk = 0;  // m/s^3, largest |1 s block jerk|
  double mean_squared_jerk = 0;  // m^2/s^6, over the 1 s jerk samples
  int lane_changes = 0;
  double min_gap_m = 0;       // +inf: never a car ahead in the ego lane
  double min_headway_s = 0;   // +inf likewise
  double plan_ms_p50 = 0, plan_ms_p99 = 0, plan_ms_max = 0;  // wall time per Plan() call
  int plan_fallbacks = 0;     // cycles whose status was not ok
  std::vector<Incident> incident_log;
  // Judging on: one judgement per incident_log entry (could a trajectory within the simulator's
  // limits have avoided it?), in JSON under each entry's "judgement" and counted in "judged".
  bool judged = false;
  std::vector<IncidentJudgement> judgements;
  // With --oracle: the best distance along the road any planner could have driven in this
  // drive's time against its traffic as it moved (oracle.h), beside the ego's own.
  bool oracle_run = false;
  OracleResult oracle;
  // Where the time went: the whole drive and each lap (following, at the limit, passes).
  LapBreakdown breakdown;
  std::vector<LapBreakdown> laps;

  double miles() const { return distance_m / units::kMetersPerMile; }
  // Incidents per mile of `kind` (0 for a drive of no distance).
  double per_mile(IncidentKind kind) const;
  nlohmann::json ToJson() const;  // infinite values become null
  std::string ToText() const;     // human-readable, several lines
};

struct AggregateReport {
  std::vector<DriveReport> episodes;  // seed order
  double total_miles = 0;
  std::array<double, kIncidentKinds> per_100_miles{};
  int incidents = 0;
  double avg_speed_mph = 0, avg_speed_stddev = 0;  // over episodes
  int worst = -1;  // index of the worst episode: most incidents per mile, then slowest
  double plan_ms_p50 = 0, plan_ms_p99 = 0, plan_ms_max = 0;  // over episodes (max of each)
  LapBreakdown breakdown;  // summed over episodes
  bool judged = false;     // the episodes' incidents were judged
  std::array<int, 4> verdicts{};  // incidents per Verdict, summed over episodes
  bool oracle_run = false;        // the episodes have an oracle search
  double oracle_mph = 0, driven_mph = 0;  // its speed and the ego's along the road, mean over episodes
  // A receding search's foresight, and its stuck windows and through_* figures summed over
  // episodes (no windows kept).
  OracleResult oracle_sum;
  static AggregateReport From(std::vector<DriveReport> episodes);
  nlohmann::json ToJson() const;
  std::string ToText() const;
};

}  // namespace frenetic::sim
