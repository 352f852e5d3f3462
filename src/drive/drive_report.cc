#include "frenetic/drive/drive_report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <spdlog/fmt/fmt.h>

#include "frenetic/json_text.h"

namespace frenetic::sim {
namespace {

std::string Maybe(double v, const char* fmt_unit) {
  return std::isfinite(v) ? fmt::format(fmt::runtime(fmt_unit), v) : std::string("none");
}

double Share(double part, double whole) { return whole > 0 ? 100.0 * part / whole : 0; }

// The "oracle" line of a report, and with a foresight (a receding search, `r`) a second one.
std::string OracleText(double oracle_mph, double driven_mph, const OracleResult& r) {
  std::string out = fmt::format(
      "oracle          {:.2f} mph along the road at best against this traffic (offline search), "
      "the ego {:.2f} mph there\n",
      oracle_mph, driven_mph);
  if (r.foresight > 0) {
    out += fmt::format(
        "                foresight {:.1f} s: {} windows stuck; where it went through ({:.0f} s), "
        "the search {:.2f} mph, the ego {:.2f} mph\n",
        r.foresight, r.stuck_windows, r.through_seconds, r.through_search_mph(),
        r.through_driven_mph());
  }
  return out;
}

// The receding search's figures of `r` (its foresight, 0 for the whole-window search) into the
// "oracle" object `out`: an episode's and the sum over episodes alike.
void AddForesightJson(const OracleResult& r, nlohmann::json* out) {
  (*out)["foresight_s"] = r.foresight;
  (*out)["stuck_windows"] = r.stuck_windows;
  (*out)["through_seconds"] = r.through_seconds;
  (*out)["through_search_mph"] = r.through_search_mph();
  (*out)["through_driven_mph"] = r.through_driven_mph();
}

nlohmann::json OracleWindowsJson(const OracleResult& r) {
  nlohmann::json arr = nlohmann::json::array();
  for (const OracleWindow& w : r.windows) {
    arr.push_back({{"t", w.t},
                   {"driven_m", w.driven_m},
                   {"best_m", w.best_m},
                   {"lanes", w.lanes},
                   {"speeds", w.speeds},
                   {"driven_lanes", w.driven_lanes},
                   {"search_m", w.search_m},
                   {"stuck_stage", w.stuck_stage}});
  }
  return arr;
}

// The windows where the search gained most on the ego, most first.
std::string OracleWorstText(const OracleResult& r, std::size_t count) {
  std::vector<const OracleWindow*> w;
  for (const OracleWindow& x : r.windows) w.push_back(&x);
  std::stable_sort(w.begin(), w.end(), [](const OracleWindow* a, const OracleWindow* b) {
    return a->best_m - a->driven_m > b->best_m - b->driven_m;
  });
  std::string out;
  for (std::size_t i = 0; i < std::min(count, w.size()) && w[i]->best_m > w[i]->driven_m; ++i) {
    out += fmt::format("  from t {:6.1f} s: {:+.1f} m; lanes searched {}, driven {}\n", w[i]->t,
                       w[i]->best_m - w[i]->driven_m, w[i]->lanes, w[i]->driven_lanes);
  }
  return out;
}

// The "time" and "passes" lines of a report.
std::string BreakdownText(const LapBreakdown& b) {
  return fmt::format(
      "time            at the limit {:.1f} s ({:.1f}%, {:.2f} mph there), following {:.1f} s ({:.1f}%), of it "
      "{:.1f} s with a neighbour lane open\n"
      "passes          {} made, {} missed (a neighbour lane open >= 3 s while following), "
      "passed by {}\n",
      b.at_limit_s, Share(b.at_limit_s, b.seconds), b.at_limit_mph(), b.following_s,
      Share(b.following_s, b.seconds), b.following_open_s, b.passes, b.missed_passes,
      b.passed_by);
}

nlohmann::json BreakdownJson(const LapBreakdown& total, const std::vector<LapBreakdown>* laps) {
  nlohmann::json j = total.ToJson();
  j.erase("lap");
  if (laps != nullptr) {
    nlohmann::json arr = nlohmann::json::array();
    for (const LapBreakdown& b : *laps) arr.push_back(b.ToJson());
    j["laps"] = std::move(arr);
  }
  return j;
}

nlohmann::json JudgementJson(const IncidentJudgement& j) {
  nlohmann::json starts = nlohmann::json::array();
  for (const StartJudgement& s : j.starts) {
    nlohmann::json o = {{"t", s.t}, {"result", ToString(s.result)}, {"blocks", s.blocks}};
    if (s.as_driven_first) o["as_driven_first"] = true;
    starts.push_back(std::move(o));
  }
  nlohmann::json o = {{"verdict", ToString(j.verdict)},
                      {"summary", Describe(j)},
                      {"until", j.until},
                      {"blocks", j.blocks},
                      {"ms", j.ms},
                      {"starts", std::move(starts)}};
  if (j.verdict == Verdict::kAvoidable) {
    o["avoidable_from"] = j.avoidable_from;
    o["last_chance"] = j.last_chance;
    o["escape"] = j.escape;
  }
  return o;
}

constexpr std::array<Verdict, 4> kVerdicts = {Verdict::kAvoidable, Verdict::kUnavoidable,
                                              Verdict::kUndecided, Verdict::kNotJudged};

// Incidents per verdict; an incident without a judgement (a drive cut short) is not judged.
std::array<int, 4> CountVerdicts(const DriveReport& r) {
  std::array<int, 4> n{};
  for (const IncidentJudgement& j : r.judgements) ++n[static_cast<int>(j.verdict)];
  if (r.incident_log.size() > r.judgements.size()) {
    n[static_cast<int>(Verdict::kNotJudged)] +=
        static_cast<int>(r.incident_log.size() - r.judgements.size());
  }
  return n;
}

nlohmann::json VerdictsJson(const std::array<int, 4>& n) {
  nlohmann::json o = nlohmann::json::object();
  for (Verdict v : kVerdicts) o[ToString(v)] = n[static_cast<int>(v)];
  return o;
}

std::string VerdictsText(const std::array<int, 4>& n) {
  return fmt::format(
      "judged          {} avoidable, {} unavoidable (the traffic's), {} undecided, {} not judged\n",
      n[0], n[1], n[2], n[3]);
}

}  // namespace

double DriveReport::per_mile(IncidentKind kind) const {
  const double mi = miles();
  return mi > 0 ? incidents_by_kind[static_cast<int>(kind)] / mi : 0;
}

nlohmann::json DriveReport::ToJson() const {
  nlohmann::json by_kind = nlohmann::json::object(), per_mile_j = nlohmann::json::object();
  for (int k = 0; k < kIncidentKinds; ++k) {
    const auto kind = static_cast<IncidentKind>(k);
    by_kind[ToString(kind)] = incidents_by_kind[k];
    per_mile_j[ToString(kind)] = per_mile(kind);
  }
  nlohmann::json log = nlohmann::json::array();
  for (std::size_t n = 0; n < incident_log.size(); ++n) {
    const Incident& i = incident_log[n];
    log.push_back({{"t", i.t}, {"s", i.s}, {"d", i.d}, {"lane", i.lane},
                   {"kind", ToString(i.kind)}, {"value", i.value}});
    if (judged) {
      log.back()["judgement"] =
          JudgementJson(n < judgements.size() ? judgements[n] : IncidentJudgement());
    }
  }
  nlohmann::json out = {
      {"scenario", scenario},
      {"planner", planner},
      {"map", map},
      {"seed", seed},
      {"stop_reason", stop_reason},
      {"distance_m", distance_m},
      {"miles", miles()},
      {"sim_seconds", sim_seconds},
      {"exchanges", exchanges},
      {"avg_speed_mph", avg_speed_mph},
      {"miles_to_first_incident", miles_to_first_incident},
      {"best_miles_without_incident", best_miles_without_incident},
      {"incidents", incidents},
      {"incidents_by_kind", by_kind},
      {"incidents_per_mile", per_mile_j},
      {"max_speed_mph", max_speed_mph},
      {"max_acc", max_acc},
      {"max_jerk", max_jerk},
      {"mean_squared_jerk", mean_squared_jerk},
      {"lane_changes", lane_changes},
      {"min_gap_m", FiniteOrNull(min_gap_m)},
      {"min_headway_s", FiniteOrNull(min_headway_s)},
      {"plan_ms", {{"p50", plan_ms_p50}, {"p99", plan_ms_p99}, {"max", plan_ms_max}}},
      {"plan_fallbacks", plan_fallbacks},
      {"breakdown", BreakdownJson(breakdown, &laps)},
      {"incident_log", log}};
  if (judged) out["judged"] = VerdictsJson(CountVerdicts(*this));
  if (oracle_run) {
    out["oracle"] = {{"seconds", oracle.seconds},
                     {"distance_m", oracle.distance_m},
                     {"mph", oracle.mph()},
                     {"driven_m", oracle.driven_m},
                     {"driven_mph", oracle.driven_mph()},
                     {"windows", OracleWindowsJson(oracle)}};
    AddForesightJson(oracle, &out["oracle"]);
  }
  return out;
}

std::string DriveReport::ToText() const {
  std::ostringstream o;
  o << fmt::format("scenario {}  seed {}  planner {}  map {}\n", scenario, seed, planner, map);
  o << fmt::format("distance        {:.1f} m ({:.3f} mi) in {:.1f} s simulated, {} exchanges ({})\n",
                   distance_m, miles(), sim_seconds, exchanges, stop_reason);
  o << fmt::format("average speed   {:.2f} mph\n", avg_speed_mph);
  o << fmt::format("first incident  after {:.3f} mi{}; best {:.3f} mi without incident\n",
                   miles_to_first_incident, incidents == 0 ? " (none)" : "",
                   best_miles_without_incident);
  o << "incidents       " << incidents;
  for (int k = 0; k < kIncidentKinds; ++k) {
    if (incidents_by_kind[k] > 0) {
      o << fmt::format("  {} {}", ToString(static_cast<IncidentKind>(k)), incidents_by_kind[k]);
    }
  }
  o << "\n";
  o << fmt::format("maxima          speed {:.2f} mph, acceleration {:.2f} m/s^2, jerk {:.2f} m/s^3\n",
                   max_speed_mph, max_acc, max_jerk);
  o << fmt::format("lane changes    {}\n", lane_changes);
  o << BreakdownText(breakdown);
  if (laps.size() > 1) {
    o << "  lap  time s    mph  at limit s  following s  (lane open)  passes  missed  passed by\n";
    for (const LapBreakdown& b : laps) {
      o << fmt::format("  {:3d}  {:6.1f}  {:5.2f}  {:10.1f}  {:11.1f}  {:11.1f}  {:6d}  {:6d}  {:9d}\n",
                       b.lap + 1, b.seconds, b.avg_speed_mph(), b.at_limit_s, b.following_s,
                       b.following_open_s, b.passes, b.missed_passes, b.passed_by);
    }
  }
  o << "closest ahead   gap " << Maybe(min_gap_m, "{:.1f} m") << ", headway "
    << Maybe(min_headway_s, "{:.2f} s") << "\n";
  o << fmt::format("planning        p50 {:.3f} ms, p99 {:.3f} ms, max {:.3f} ms; {} fallback cycles\n",
                   plan_ms_p50, plan_ms_p99, plan_ms_max, plan_fallbacks);
  if (oracle_run) {
    o << OracleText(oracle.mph(), oracle.driven_mph(), oracle) << OracleWorstText(oracle, 3);
  }
  if (judged) o << VerdictsText(CountVerdicts(*this));
  for (std::size_t n = 0; n < incident_log.size(); ++n) {
    const Incident& i = incident_log[n];
    o << fmt::format("  t {:8.2f} s  s {:8.1f}  d {:6.2f}  lane {:2d}  {:<12} {:.2f}\n", i.t, i.s,
                     i.d, i.lane, ToString(i.kind), i.value);
    if (judged) {
      const IncidentJudgement j = n < judgements.size() ? judgements[n] : IncidentJudgement();
      o << "      " << Describe(j);
      if (j.verdict == Verdict::kAvoidable) o << "; escape: " << j.escape;
      o << "\n";
    }
  }
  return o.str();
}

AggregateReport AggregateReport::From(std::vector<DriveReport> episodes) {
  AggregateReport a;
  a.episodes = std::move(episodes);
  std::array<int, kIncidentKinds> counts{};
  double sum_speed = 0;
  for (const DriveReport& r : a.episodes) {
    a.total_miles += r.miles();
    a.incidents += r.incidents;
    for (int k = 0; k < kIncidentKinds; ++k) counts[k] += r.incidents_by_kind[k];
    sum_speed += r.avg_speed_mph;
    a.plan_ms_p50 = std::max(a.plan_ms_p50, r.plan_ms_p50);
    a.plan_ms_p99 = std::max(a.plan_ms_p99, r.plan_ms_p99);
    a.plan_ms_max = std::max(a.plan_ms_max, r.plan_ms_max);
    a.breakdown.Add(r.breakdown);
    if (r.oracle_run) {
      a.oracle_run = true;
      a.oracle_mph += r.oracle.mph();
      a.driven_mph += r.oracle.driven_mph();
      OracleResult& sum = a.oracle_sum;
      sum.foresight = r.oracle.foresight;
      sum.stuck_windows += r.oracle.stuck_windows;
      sum.through_seconds += r.oracle.through_seconds;
      sum.through_search_m += r.oracle.through_search_m;
      sum.through_driven_m += r.oracle.through_driven_m;
    }
    if (r.judged) {
      a.judged = true;
      const std::array<int, 4> n = CountVerdicts(r);
      for (std::size_t v = 0; v < n.size(); ++v) a.verdicts[v] += n[v];
    }
  }
  for (int k = 0; k < kIncidentKinds; ++k) {
    a.per_100_miles[k] = a.total_miles > 0 ? 100.0 * counts[k] / a.total_miles : 0;
  }
  const double n = static_cast<double>(a.episodes.size());
  if (n > 0) {
    a.oracle_mph /= n;
    a.driven_mph /= n;
    a.avg_speed_mph = sum_speed / n;
    double var = 0;
    for (const DriveReport& r : a.episodes) {
      var += (r.avg_speed_mph - a.avg_speed_mph) * (r.avg_speed_mph - a.avg_speed_mph);
    }
    a.avg_speed_stddev = std::sqrt(var / n);
  }
  // Worst: most incidents per mile, then the slowest; ties keep the first seed.
  double worst_rate = -1, worst_speed = 0;
  for (std::size_t i = 0; i < a.episodes.size(); ++i) {
    const DriveReport& r = a.episodes[i];
    const double rate = r.miles() > 0 ? r.incidents / r.miles()
                                      : (r.incidents > 0 ? std::numeric_limits<double>::max() : 0);
    if (rate > worst_rate || (rate == worst_rate && r.avg_speed_mph < worst_speed)) {
      worst_rate = rate;
      worst_speed = r.avg_speed_mph;
      a.worst = static_cast<int>(i);
    }
  }
  return a;
}

nlohmann::json AggregateReport::ToJson() const {
  nlohmann::json per100 = nlohmann::json::object();
  for (int k = 0; k < kIncidentKinds; ++k) {
    per100[ToString(static_cast<IncidentKind>(k))] = per_100_miles[k];
  }
  nlohmann::json eps = nlohmann::json::array();
  for (const DriveReport& r : episodes) eps.push_back(r.ToJson());
  nlohmann::json out = {
      {"episodes", static_cast<int>(episodes.size())},
      {"total_miles", total_miles},
      {"incidents", incidents},
      {"incidents_per_100_miles", per100},
      {"avg_speed_mph", avg_speed_mph},
      {"avg_speed_stddev_mph", avg_speed_stddev},
      {"worst_episode", worst >= 0 ? nlohmann::json(episodes[worst].seed) : nlohmann::json()},
      {"plan_ms", {{"p50", plan_ms_p50}, {"p99", plan_ms_p99}, {"max", plan_ms_max}}},
      {"breakdown", BreakdownJson(breakdown, nullptr)},
      {"per_episode", eps}};
  if (judged) out["judged"] = VerdictsJson(verdicts);
  if (oracle_run) {
    out["oracle"] = {{"mph", oracle_mph}, {"driven_mph", driven_mph}};
    AddForesightJson(oracle_sum, &out["oracle"]);
  }
  return out;
}

std::string AggregateReport::ToText() const {
  std::ostringstream o;
  o << fmt::format("episodes        {}  total {:.2f} mi, {} incidents\n", episodes.size(),
                   total_miles, incidents);
  o << "per 100 miles  ";
  for (int k = 0; k < kIncidentKinds; ++k) {
    o << fmt::format(" {} {:.2f}", ToString(static_cast<IncidentKind>(k)), per_100_miles[k]);
  }
  o << "\n";
  o << fmt::format("average speed   {:.2f} mph (sd {:.2f} over episodes)\n", avg_speed_mph,
                   avg_speed_stddev);
  o << fmt::format("planning        p50 {:.3f} ms, p99 {:.3f} ms, max {:.3f} ms (worst episode)\n",
                   plan_ms_p50, plan_ms_p99, plan_ms_max);
  o << BreakdownText(breakdown);
  if (oracle_run) {
    o << OracleText(oracle_mph, driven_mph, oracle_sum);
  }
  for (const DriveReport& r : episodes) {
    o << fmt::format("  seed {:<6} {:7.3f} mi  {:6.2f} mph  {:3d} incidents  first after {:.3f} mi",
                     r.seed, r.miles(), r.avg_speed_mph, r.incidents, r.miles_to_first_incident);
    if (r.oracle_run) o << fmt::format("  oracle {:.2f} mph", r.oracle.mph());
    o << "\n";
  }
  if (worst >= 0) {
    o << fmt::format("worst episode   seed {} ({} incidents in {:.3f} mi)\n", episodes[worst].seed,
                     episodes[worst].incidents, episodes[worst].miles());
  }
  if (judged) {
    o << VerdictsText(verdicts);
    for (const DriveReport& r : episodes) {
      for (std::size_t n = 0; n < r.incident_log.size() && r.judged; ++n) {
        const IncidentJudgement j = n < r.judgements.size() ? r.judgements[n] : IncidentJudgement();
        o << fmt::format("  seed {:<6} t {:7.2f} s  {:<12} {}\n", r.seed, r.incident_log[n].t,
                         ToString(r.incident_log[n].kind), Describe(j));
      }
    }
  }
  return o.str();
}

}  // namespace frenetic::sim
