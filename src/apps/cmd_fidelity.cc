// `frenetic fidelity --recordings DIR`: the headless simulator checked against recordings of the
// real Unity simulator (protocol, chord Frenet, ego motion, traffic statistics). Exit status 0
// when every check passes, 1 when one fails, 2 on bad input (one-line error on stderr).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "frenetic/cores.h"
#include "frenetic/drive/traffic_runs.h"
#include "frenetic/eval/fidelity.h"
#include "frenetic/json_text.h"
#include "frenetic/plan/planner_config.h"
#include "frenetic/sim/world.h"

namespace frenetic::apps {
namespace {

struct FidelityArgs {
  std::string recordings;
  std::string map;
  std::string planner = "search";
  std::string traffic_planner = "baseline";
  std::string traffic_ego = "replay";
  std::string config;
  std::string scenario = "udacity";
  std::vector<std::string> checks = {"protocol", "frenet", "ego", "traffic"};
  double minutes = 30;
  double episode_seconds = 120;
  std::uint64_t seed = 1;
  int jobs = 0;
  bool json = false;
};

bool Wants(const FidelityArgs& a, const char* check) {
  return std::find(a.checks.begin(), a.checks.end(), check) != a.checks.end();
}

std::string Number(double v) {
  if (std::isinf(v)) return "inf";
  if (std::isnan(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

int Error(const std::string& message) {
  std::fprintf(stderr, "frenetic fidelity: %s\n", message.c_str());
  return 2;
}

int RunFidelity(const FidelityArgs& args) {
  namespace fs = std::filesystem;
  const auto t0 = std::chrono::steady_clock::now();
  const std::string map_path =
      args.map.empty() ? (fs::path(args.recordings) / ".." / ".." / "data" / "highway_map.csv")
                             .lexically_normal()
                             .string()
                       : args.map;
  std::error_code ec;
  if (!fs::is_regular_file(map_path, ec)) {
    return Error("map " + map_path + " not found (the recordings are from the Udacity map; " +
                 "pass --map FILE)");
  }
  auto recordings = sim::LoadRecordings(args.recordings);
  if (!recordings.ok()) return Error(recordings.message());
  auto world = sim::LoadWorld(map_path);
  if (!world.ok()) return Error(world.message());
  if (!(*world)->is_udacity_map) {
    spdlog::warn("{} is not the Udacity map: the recordings will not match it", map_path);
  }
  auto config = args.config.empty() ? plan::PlannerConfig::LoadDefault()
                                    : plan::PlannerConfig::Load(args.config);
  if (!config.ok()) return Error(config.message());
  long messages = 0;
  for (const auto& r : *recordings) messages += static_cast<long>(r.messages.size());

  sim::CheckReport report;
  if (Wants(args, "protocol")) {
    auto planner = plan::MakePlanner(args.planner, *config, (*world)->line);
    if (!planner.ok()) return Error(planner.message());
    report.Append(sim::CheckProtocol(*recordings, **planner));
  }
  if (Wants(args, "frenet")) report.Append(sim::CheckFrenet(*recordings, sim::ChordFrenetFn(*world)));
  if (Wants(args, "ego")) report.Append(sim::CheckEgoMotion(*recordings, sim::SimulatorEgoModel()));

  std::vector<sim::StatRow> stats;
  std::string traffic_setup;
  if (Wants(args, "traffic")) {
    sim::TrafficRunOptions options;
    auto scenario = sim::LoadScenario(args.scenario);
    if (!scenario.ok()) {
      if (args.scenario != "udacity") return Error(scenario.message());
      // Until config/scenarios/udacity.yaml exists the built-in defaults are the udacity scenario.
      spdlog::warn("{}; using the built-in udacity defaults", scenario.message());
      scenario = sim::Scenario{};
    }
    options.scenario = *scenario;
    options.planner = args.traffic_planner;
    if (args.traffic_ego == "replay") {
      for (const auto& r : *recordings) {
        sim::EgoProfile p = sim::RecordingEgoProfile(r);
        if (p.duration() > 0) options.ego_profiles.push_back(std::move(p));
      }
      if (options.ego_profiles.empty()) {
        return Error("--traffic-ego replay: no recording covers any simulated time");
      }
    }
    options.minutes = args.minutes;
    options.episode_seconds = args.episode_seconds;
    options.first_seed = args.seed;
    options.jobs = args.jobs > 0 ? args.jobs : UsableCores();
    sim::TrafficStatsBuilder real((*world)->track.max_s);
    for (const auto& r : *recordings) real.AddRun(sim::RecordingTrafficSamples(r));
    auto simulated = sim::SimulateTraffic(*world, options, args.config);
    if (!simulated.ok()) return Error(simulated.message());
    stats = sim::CompareTraffic(real.figures(), *simulated);
    report.Append(sim::TrafficReport(stats));
    const int episodes = sim::TrafficEpisodes(options);
    std::string ego;
    if (options.ego_profiles.empty()) {
      ego = "ego: planner " + args.traffic_planner + ", " + std::to_string(episodes) + " x " +
            Number(options.episode_seconds) + " s";
    } else {
      ego = "ego: replays the recorded ego's speed (as a cap) and lane, " +
            std::to_string(episodes) + " episodes cycling over " +
            std::to_string(options.ego_profiles.size()) + " recordings";
    }
    traffic_setup = "scenario " + options.scenario.name + ", " + ego +
                    " from the start pose (seeds " + std::to_string(args.seed) + "..), " +
                    "latency mode l_old " + std::to_string(options.scenario.timing.l_old_min) +
                    "-" + std::to_string(options.scenario.timing.l_old_max) + ", l_new " +
                    std::to_string(options.scenario.timing.l_new_min) + "-" +
                    std::to_string(options.scenario.timing.l_new_max);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const bool ok = report.ok();

  if (args.json) {
    nlohmann::json j;
    j["ok"] = ok;
    j["map"] = map_path;
    j["recordings"] = nlohmann::json::array();
    for (const auto& r : *recordings) {
      j["recordings"].push_back({{"name", r.name}, {"messages", r.messages.size()}});
    }
    j["checks"] = nlohmann::json::array();
    for (const auto& row : report.rows) {
      j["checks"].push_back({{"check", row.check},
                             {"cases", row.cases},
                             {"passed", row.passed},
                             {"worst", FiniteOrNull(row.worst)},
                             {"tolerance", row.tolerance},
                             {"unit", row.unit},
                             {"ok", row.ok()},
                             {"failures", row.failures}});
    }
    j["traffic"] = nlohmann::json::array();
    for (const auto& s : stats) {
      j["traffic"].push_back({{"statistic", s.name},
                              {"unit", s.unit},
                              {"real", FiniteOrNull(s.real)},
                              {"sim", FiniteOrNull(s.sim)},
                              {"ratio", FiniteOrNull(s.ratio)},
                              {"band", {s.lo, s.hi}},
                              {"real_samples", s.real_n},
                              {"sim_samples", s.sim_n},
                              {"ok", s.ok()}});
    }
    if (!traffic_setup.empty()) j["traffic_setup"] = traffic_setup;
    j["quirks"] = nlohmann::json::array();
    for (const auto& q : report.quirks) {
      j["quirks"].push_back(
          {{"check", q.check}, {"quirk", q.name}, {"count", q.count}, {"note", q.note}});
    }
    j["wall_seconds"] = seconds;
    std::printf("%s\n", JsonText(j, 2).c_str());
    return ok ? 0 : 1;
  }

  std::printf("frenetic fidelity: %zu recordings, %ld real messages (%s), map %s\n\n",
              recordings->size(), messages, args.recordings.c_str(), map_path.c_str());
  std::printf("%-56s %7s %7s %10s %10s  %s\n", "check", "cases", "passed", "worst", "tolerance",
              "unit");
  for (const auto& row : report.rows) {
    std::printf("%-56s %7ld %7ld %10s %10s  %-6s %s\n", row.check.c_str(), row.cases, row.passed,
                Number(row.worst).c_str(), Number(row.tolerance).c_str(), row.unit.c_str(),
                row.ok() ? "ok" : "FAIL");
  }
  if (!stats.empty()) {
    std::printf("\ntraffic, real recordings vs simulated (%s):\n", traffic_setup.c_str());
    std::printf("%-36s %7s %10s %10s %7s %11s %8s %8s\n", "statistic", "unit", "real", "sim",
                "ratio", "band", "n real", "n sim");
    for (const auto& s : stats) {
      char band[32];
      std::snprintf(band, sizeof band, "%.2f-%.2f", s.lo, s.hi);
      std::printf("%-36s %7s %10s %10s %7s %11s %8ld %8ld  %s\n", s.name.c_str(), s.unit.c_str(),
                  Number(s.real).c_str(), Number(s.sim).c_str(), Number(s.ratio).c_str(), band,
                  s.real_n, s.sim_n, s.ok() ? "ok" : "FAIL");
    }
  }
  if (!report.quirks.empty()) {
    std::printf("\ndocumented quirks, counted apart:\n");
    for (const auto& q : report.quirks) {
      std::printf("  %-8s %-70s %7ld  %s\n", q.check.c_str(), q.name.c_str(), q.count,
                  q.note.c_str());
    }
  }
  bool any_failure = false;
  for (const auto& row : report.rows) {
    if (row.ok()) continue;
    if (!any_failure) std::printf("\nfailures:\n");
    any_failure = true;
    std::printf("  %s:\n", row.check.c_str());
    for (const auto& f : row.failures) std::printf("    %s\n", f.c_str());
  }
  std::printf("\nresult: %s (%zu checks, %.1f s)\n", ok ? "PASS" : "FAIL", report.rows.size(),
              seconds);
  return ok ? 0 : 1;
}

}  // namespace

void RegisterFidelity(CLI::App& app) {
  auto args = std::make_shared<FidelityArgs>();
  auto* sub = app.add_subcommand(
      "fidelity",
      "Check the headless simulator against recordings of the real Udacity simulator: the wire\n"
      "protocol (every real message parsed and answered), the chord-based Frenet of the ego,\n"
      "every sensor_fusion row and end_path, the ego's path trimming and consumption (previous\n"
      "path, position, speed, yaw of the next message), and traffic statistics side by side.\n"
      "Prints a table; exits 1 when a check fails, 2 on bad input.");
  sub->add_option("--recordings", args->recordings,
                  "Directory of real recordings: pairs *input-NAME.json (telemetry objects, one\n"
                  "per line) and *response-NAME.json (the planner's reply frames)")
      ->required();
  sub->add_option("--map", args->map,
                  "Map the recordings were made on (default: DIR/../../data/highway_map.csv)");
  sub->add_option("--planner", args->planner,
                  "Planner answering the real messages (default: search)")
      ->check(CLI::IsMember({"search", "baseline"}));
  sub->add_option("--traffic-planner", args->traffic_planner,
                  "Planner driving the ego in the traffic runs (default: baseline, ~50x cheaper\n"
                  "than search; the traffic statistics change little with it)")
      ->check(CLI::IsMember({"search", "baseline"}));
  sub->add_option("--config", args->config,
                  "Planner configuration YAML (default: config/planner.yaml)");
  sub->add_option("--traffic-ego", args->traffic_ego,
                  "Who drives the ego in the traffic runs: replay (default; a scripted ego\n"
                  "drives each recording's speed profile and lanes, so that traffic queues\n"
                  "behind it as in the recordings) or planner (--traffic-planner, episodes of\n"
                  "--episode-seconds)")
      ->check(CLI::IsMember({"replay", "planner"}));
  sub->add_option("--scenario", args->scenario,
                  "Scenario whose traffic is compared, name or YAML file (default: udacity)");
  sub->add_option("--checks", args->checks,
                  "Checks to run (default: protocol frenet ego traffic)")
      ->check(CLI::IsMember({"protocol", "frenet", "ego", "traffic"}))
      ->delimiter(',');
  sub->add_option("--minutes", args->minutes,
                  "Simulated minutes of traffic in total, min (default: 30)")
      ->check(CLI::Range(0.1, 1000.0));
  sub->add_option("--episode-seconds", args->episode_seconds,
                  "Length of each traffic episode, s; each starts from the start pose like the\n"
                  "recordings (default: 120)")
      ->check(CLI::Range(5.0, 100000.0));
  sub->add_option("--seed", args->seed, "First episode seed; episodes use seed, seed+1, ... "
                                        "(default: 1)");
  sub->add_option("--jobs", args->jobs,
                  "Threads for the traffic episodes, 0 = every core this process may use (its CPU\n"
                  "affinity: taskset; default: 0); results do not depend on it")
      ->check(CLI::Range(0, 256));
  sub->add_flag("--json", args->json, "Print the results as one JSON object on stdout");
  sub->callback([args] { ExitWith(RunFidelity(*args)); });
}

}  // namespace frenetic::apps
