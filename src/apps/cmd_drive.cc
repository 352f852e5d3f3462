// frenetic drive: runs a planner in the headless simulator, faster than real time, and reports
// what the Udacity simulator would have measured.
#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "apps/commands.h"
#include "apps/drive_connect.h"
#include "frenetic/drive/episode.h"
#include "frenetic/drive/record.h"
#include "frenetic/json_text.h"
#include "frenetic/map/track.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"
#include "frenetic/record/plan_json.h"
#include "frenetic/sim/scenario.h"
#include "frenetic/sim/world.h"
#include "frenetic/units.h"

namespace frenetic::apps {
namespace {

struct DriveArgs {
  std::string map_path;
  std::string scenario = "udacity";
  std::int64_t seed = -1;
  double laps = 0, miles = 0, seconds = 0;
  std::string planner = "search";
  std::string config_path;
  std::string record_path;
  bool json = false;
  std::string latency;
  int episodes = 1;
  int jobs = 0;
  bool progress = false;
  bool no_judge = false;
  bool oracle = false;
  double oracle_headway = sim::OracleOptions().headway;
  double oracle_room = sim::OracleOptions().room_behind;
  double oracle_foresight = sim::OracleOptions().foresight;
  double perfect_predictions = 0;
  int judge_budget = sim::JudgeOptions().budget_blocks;
  bool no_timing = false;
  bool real_time_deadlines = false;
  std::string connect;
  bool realtime = false;
};

int Fail(const std::string& message) {
  std::fprintf(stderr, "frenetic drive: %s\n", message.c_str());
  return 1;
}

namespace drive_internal {
std::string Clock(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  return fmt::format("{}:{:02d}:{:02d}", s / 3600, s / 60 % 60, s % 60);
}
}  // namespace drive_internal

// The progress line of `drive --episodes N` on stderr: on a terminal one line rewritten in
// place (at most 4 times a second); otherwise one line per finished episode, at most one every
// 5 s, and always the last.
class ProgressLine {
 public:
  explicit ProgressLine(bool tty) : tty_(tty), start_(Clock::now()) {}

  void Update(const sim::EpisodesProgress& p) {
    const auto now = Clock::now();
    const double since = std::chrono::duration<double>(now - last_).count();
    const bool last = p.done == p.total && p.episode_finished;
    if (tty_) {
      if (!last && !p.episode_finished && printed_ && since < 0.25) return;
    } else {
      if (!p.episode_finished || (!last && printed_ && since < 5.0)) return;
    }
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const std::string eta =
        p.done > 0 ? drive_internal::Clock(elapsed * (p.total - p.done) / p.done) : "-:--:--";
    const std::string line =
        fmt::format("episodes {}/{}  elapsed {}  ETA {}  {:.1f} mi  {} incident{}", p.done, p.total,
                    drive_internal::Clock(elapsed), eta, p.miles + p.running_miles, p.incidents,
                    p.incidents == 1 ? "" : "s");
    if (tty_) {
      std::fprintf(stderr, "\r%-78s%s", line.c_str(), last ? "\n" : "");
    } else {
      std::fprintf(stderr, "%s\n", line.c_str());
    }
    std::fflush(stderr);
    printed_ = true;
    last_ = now;
  }

 private:
  using Clock = std::chrono::steady_clock;
  bool tty_;
  Clock::time_point start_, last_;
  bool printed_ = false;
};

int Drive(const DriveArgs& a) {
  auto scenario = sim::LoadScenario(a.scenario);
  if (!scenario.ok()) return Fail(scenario.message());
  if (!a.latency.empty()) {
    auto mode = sim::ParseTimingMode(a.latency);
    if (!mode.ok()) return Fail("--latency: " + mode.message());
    scenario->timing.mode = *mode;
  }
  const std::uint64_t seed = a.seed >= 0 ? static_cast<std::uint64_t>(a.seed) : scenario->seed;
  sim::EpisodeLimits limits;
  limits.laps = a.laps;
  limits.miles = a.miles;
  limits.seconds = a.seconds;
  if (a.laps <= 0 && a.miles <= 0 && a.seconds <= 0) limits.laps = 1;
  if (Status s = limits.Validate(); !s.ok()) return Fail(s.message());

  const std::string map_path = a.map_path.empty() ? map::DefaultTrackPath() : a.map_path;
  auto world = sim::LoadWorld(map_path);
  if (!world.ok()) return Fail(world.message());

  sim::JudgeOptions judge;
  judge.budget_blocks = a.judge_budget;
  sim::OracleOptions oracle;
  oracle.headway = a.oracle_headway;
  oracle.room_behind = a.oracle_room;
  oracle.foresight = a.oracle_foresight;
  if (a.oracle) {
    // CLI's ranges let NaN through.
    if (Status s = oracle.Validate(); !s.ok()) {
      return Fail("--oracle-headway, --oracle-room, --oracle-foresight: " + s.message());
    }
  }
  if (!(a.perfect_predictions == 0 ||
        (a.perfect_predictions >= 0.5 && a.perfect_predictions <= 10))) {  // NaN too
    return Fail("--perfect-predictions must be 0 or 0.5..10 s");
  }
  if (!a.connect.empty()) {
    if (a.episodes > 1) return Fail("--connect drives one episode (--episodes 1)");
    if (a.oracle) return Fail("--oracle needs the traffic's history: drive in-process (no --connect)");
    if (a.perfect_predictions > 0) {
      return Fail("--perfect-predictions reads the simulator: drive in-process (no --connect)");
    }
    ConnectOptions connect;
    connect.url = a.connect;
    connect.realtime = a.realtime;
    connect.timing = !a.no_timing;
    if (!a.no_judge) connect.judge = judge;
    std::unique_ptr<sim::RecordWriter> record;
    if (!a.record_path.empty()) {
      auto writer = sim::RecordWriter::Open(a.record_path);
      if (!writer.ok()) return Fail(writer.message());
      record = std::move(writer).value();
      connect.record = record.get();
    }
    auto report = DriveOverNetwork(*world, *scenario, seed, limits, connect);
    if (!report.ok()) return Fail(report.message());
    std::printf("%s", a.json ? (JsonText(report->ToJson()) + "\n").c_str() : report->ToText().c_str());
    return 0;
  }

  const std::string config_path =
      a.config_path.empty() ? plan::PlannerConfig::DefaultPath() : a.config_path;
  auto config = plan::PlannerConfig::Load(config_path);
  if (!config.ok()) return Fail(config.message());
  // Latency is counted in ticks here, so wall-clock deadlines would only make a seed's result
  // depend on the machine's load.
  if (!a.real_time_deadlines) config->PinDeadlines();
  auto shared_config = std::make_shared<const plan::PlannerConfig>(std::move(config).value());
  std::shared_ptr<const map::ReferenceLine> line = (*world)->line;
  const std::string planner_name = a.planner;
  sim::PlannerFactory factory = [planner_name, shared_config, line] {
    return plan::MakePlanner(planner_name, *shared_config, line);
  };
  auto probe = factory();
  if (!probe.ok()) return Fail("planner \"" + planner_name + "\": " + probe.message());

  const bool tty = isatty(fileno(stderr)) != 0;
  if (a.episodes > 1) {
    if (!a.record_path.empty()) return Fail("--record needs a single episode (--episodes 1)");
    sim::EpisodesOptions options;
    options.timing = !a.no_timing;
    if (!a.no_judge) options.judge = judge;
    if (a.oracle) options.oracle = oracle;
    options.foresee = a.perfect_predictions;
    std::unique_ptr<ProgressLine> line;
    if (a.progress || tty) {
      line = std::make_unique<ProgressLine>(tty);
      options.progress = [&line](const sim::EpisodesProgress& p) { line->Update(p); };
    }
    auto agg =
        sim::RunEpisodes(*world, *scenario, seed, a.episodes, a.jobs, limits, factory, options);
    if (!agg.ok()) return Fail(agg.message());
    if (a.json) {
      std::printf("%s\n", JsonText(agg->ToJson()).c_str());
    } else {
      std::printf("%s", agg->ToText().c_str());
    }
    return 0;
  }

  std::unique_ptr<sim::RecordWriter> record;
  sim::RunOptions options;
  options.timing = !a.no_timing;
  if (!a.no_judge) options.judge = judge;
  if (a.oracle) options.oracle = oracle;
  options.foresee = a.perfect_predictions;
  if (!a.record_path.empty()) {
    auto writer = sim::RecordWriter::Open(a.record_path);
    if (!writer.ok()) return Fail(writer.message());
    record = std::move(writer).value();
    options.record = record.get();
    // A replica traces the candidates on the record's thread, so the planner that drives does
    // not (drive/record.h); with wall-clock deadlines only the planner itself knows its search.
    // (Not with perfect predictions: the record does not keep them for a replica.)
    if (auto replica = factory();
        replica.ok() && !a.real_time_deadlines && !(a.perfect_predictions > 0)) {
      record->TraceByReplay(std::move(replica).value(), options.trace_candidates);
      options.trace_candidates = 0;
    }
    std::ifstream in(config_path);
    std::stringstream text;
    text << in.rdbuf();
    options.planner_config = record::YamlToJson(text.str());
  }
  if (a.progress || tty) {
    options.progress = [](const sim::Episode& ep) {
      if (ep.exchanges() % 50 != 0 && !ep.done()) return;
      const sim::Simulator& s = ep.sim();
      std::fprintf(stderr, "\r%8.1f m  %6.1f s  %5.1f mph  %d incidents   ", s.monitor().distance(),
                   s.time(), s.ego().speed() * units::kSimMpsToMph, s.monitor().total());
      if (ep.done()) std::fprintf(stderr, "\n");
    };
  }
  auto report = sim::RunEpisode(*world, *scenario, seed, limits, **probe, options);
  if (!report.ok()) return Fail(report.message());
  if (a.json) {
    std::printf("%s\n", JsonText(report->ToJson()).c_str());
  } else {
    std::printf("%s", report->ToText().c_str());
  }
  return 0;
}

}  // namespace

void RegisterDrive(CLI::App& app) {
  auto args = std::make_shared<DriveArgs>();
  auto* sub = app.add_subcommand(
      "drive",
      "Drive a planner in the headless Udacity-faithful simulator, faster than real time, and "
      "report distance, speed, incidents (as the simulator counts them) and planning time.\n"
      "Incidents are results: the exit status is 0 unless the run itself failed (1).");
  sub->add_option("--map", args->map_path,
                  "Track file (x y s dx dy per line). Default: the bundled track " +
                      map::DefaultTrackPath());
  sub->add_option("--scenario", args->scenario,
                  "Scenario name (config/scenarios/NAME.yaml) or YAML file. Default: udacity");
  sub->add_option("--seed", args->seed,
                  "Random seed of traffic and latency (integer >= 0). Default: the scenario's")
      ->check(CLI::NonNegativeNumber);
  auto* laps = sub->add_option("--laps", args->laps, "Length in laps of the track. Default: 1")
                   ->check(CLI::PositiveNumber);
  auto* miles = sub->add_option("--miles", args->miles, "Length in miles driven")
                    ->check(CLI::PositiveNumber);
  auto* secs = sub->add_option("--seconds", args->seconds, "Length in simulated seconds")
                   ->check(CLI::PositiveNumber);
  laps->excludes(miles, secs);
  miles->excludes(secs);
  sub->add_option("--planner", args->planner, "Planner: search or baseline. Default: search");
  sub->add_option("--config", args->config_path,
                  "Planner configuration YAML. Default: config/planner.yaml");
  sub->add_option("--record", args->record_path,
                  "Write one JSON line per exchange to this file (header, exchanges, footer), "
                  "for `frenetic report`; gzip-compressed when the name ends in .gz (~10-17 MB "
                  "a lap instead of ~95-180 MB). With --connect the planner's internals "
                  "(candidates, costs) are unknown and left out. Default: no record");
  sub->add_flag("--json", args->json, "Print the report as one JSON object on stdout");
  sub->add_option("--latency", args->latency,
                  "Timing: lockstep (1 tick per exchange), fixed (the scenario's l_old, l_new "
                  "ticks) or random (its ranges). Default: the scenario's (udacity: lockstep)");
  sub->add_option("--episodes", args->episodes,
                  "Run N episodes with seeds seed, seed+1, ... and report the aggregate. "
                  "Default: 1")
      ->check(CLI::Range(1, 100000));
  sub->add_option("--jobs", args->jobs,
                  "Threads for --episodes (0 = every core this process may use, its CPU affinity: "
                  "taskset). Results do not depend on it. "
                  "Default: 0")
      ->check(CLI::Range(0, 1024));
  sub->add_flag("--progress", args->progress,
                "Show the progress on stderr even when it is not a terminal (one episode: "
                "distance, time, speed, incidents; --episodes N: episodes done, elapsed time, "
                "ETA, miles and incidents, a line per episode at most every 5 s). Default: on "
                "a terminal only");
  sub->add_flag("--no-judge", args->no_judge,
                "Do not judge the incidents. Default: every incident is judged: a search from the "
                "ego's state at every 0.2 s of the 3 s before it, over trajectories within the "
                "simulator's limits against the traffic as it moved, reports \"avoidable from "
                "t = ...\" or \"unavoidable\" (the traffic's) in the report and the JSON. Cost: "
                "the history kept while driving is not measurable; a search takes ~2.5 us of CPU "
                "per 0.2 s block tried, a few ms for a typical incident");
  CLI::Option* oracle_flag = sub->add_flag("--oracle", args->oracle,
                "After each episode, search how far a planner that knew the traffic's next 20 s "
                "could have driven against it as it moved (frenetic/eval/oracle.h): dynamic "
                "programming over lanes, positions (0.5 m) and speeds (1 m/s steps up to 22.2 "
                "m/s = 49.7 mph along the road) every 0.5 s, +4/-6 m/s^2 at most, lane changes "
                "of 3 s (1 s astride), with the planner's margins (--oracle-headway, --oracle-room), in "
                "20 s windows each started from the ego's state as it drove. Reports its mph "
                "along the road beside the ego's, and the three windows where it gained most "
                "with both lane sequences (JSON: every window). Cost: ~1.5 s of CPU per lap. "
                "Default: off");
  sub->add_option("--oracle-headway", args->oracle_headway,
                  "With --oracle: s of the ego's speed kept to a car ahead, on top of one car "
                  "length. Default: 0.5 (the planner's check.headway_min)")
      ->check(CLI::Range(0.0, 5.0))
      ->needs(oracle_flag);
  sub->add_option("--oracle-room", args->oracle_room,
                  "With --oracle: m of room (on top of one car length, plus 1 s of its closing "
                  "speed) left behind when moving in front of a car in another lane. Default: 5 "
                  "(the planner's)")
      ->check(CLI::Range(0.0, 50.0))
      ->needs(oracle_flag);
  sub->add_option("--oracle-foresight", args->oracle_foresight,
                  "With --oracle: s of the traffic's future the search may know (rounded to whole "
                  "0.5 s stages). 0: the whole 20 s window. Else a receding search: at every "
                  "0.5 s it plans this far ahead and takes the first 0.5 s, what a planner that "
                  "foresaw the traffic that long could have driven. It keeps no reserve for what "
                  "it cannot see, so a window where it finds no way on is stuck; the report adds "
                  "the stuck windows and, over the others, the search's mph and the ego's "
                  "(JSON: oracle.stuck_windows, through_search_mph, through_driven_mph; each "
                  "window's search_m and stuck_stage). Cost against the whole window's search: "
                  "about 0.2x at 3 s, 2x at 6 s, 10x at 10 s. Default: 0")
      ->check(CLI::Number & (CLI::IsMember({0.0}) | CLI::Range(0.5, 20.0)))
      ->needs(oracle_flag);
  sub->add_option("--perfect-predictions", args->perfect_predictions,
                  "A diagnostic: hand the planner every car's next S s exactly with each "
                  "telemetry, read from a copy of the simulator run ahead with the ego on its "
                  "path (then on along the road), as CommonRoad's recorded predictions are. What "
                  "the planner drives when prediction is no longer its limit; it changes the "
                  "drive. In-process only. Cost: a copy run S s ahead per exchange (about 6x the "
                  "drive's time at 6 s). Set prediction.lane_change_ghosts: 0 in --config to drop "
                  "the hedge against futures it now knows. Default: 0 (off)")
      ->check(CLI::Number & (CLI::IsMember({0.0}) | CLI::Range(0.5, 10.0)));
  sub->add_option("--judge-budget", args->judge_budget,
                  "Judging: 0.2 s blocks simulated per start before a search gives up (the start "
                  "is then undecided, never unavoidable). Default: " +
                      std::to_string(sim::JudgeOptions().budget_blocks))
      ->check(CLI::Range(1, 100000000));
  sub->add_flag("--real-time-deadlines", args->real_time_deadlines,
                "Apply the planner's wall-clock deadlines (budget_ms, refine.budget_ms) as "
                "configured. Default: off - the headless simulator counts latency in ticks, so "
                "the deadlines are switched off and every run of a seed gives the "
                "same drive whatever the machine's load (planning times are still measured)");
  sub->add_flag("--no-timing", args->no_timing,
                "Report and record planning times (with --connect: round trips) as 0, so the "
                "same seed gives byte-identical records");
  sub->add_option("--connect", args->connect,
                  "Play the simulator's side over a WebSocket against a planner server, e.g. "
                  "ws://127.0.0.1:4567/socket.io/?EIO=4&transport=websocket (planning times are "
                  "then round-trip times). Default: drive in-process");
  sub->add_flag("--realtime", args->realtime,
                "With --connect: pace the exchange at simulated time, 50 ticks per second, as "
                "the Unity simulator does. Default: as fast as the server answers");
  sub->callback([args] { ExitWith(Drive(*args)); });
}

}  // namespace frenetic::apps
