// `frenetic tune`: searches planner cost weights (and any declared planner parameter) against a
// seeded scenario suite, on every core and, under mpirun, on every rank; writes the tuned planner
// config and prints default vs tuned on the training and held-out seeds.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "apps/commands.h"
#include "frenetic/json_text.h"
#include "frenetic/tune/cluster.h"
#include "frenetic/tune/suite.h"
#include "frenetic/tune/tuner.h"

namespace frenetic::apps {
namespace {

struct TuneArgs {
  std::string suite;
  std::string output;
  std::string map;
  int budget = 0;
  int jobs = 0;
  std::string resume;
  std::string log;
  bool json = false;
};

std::string Duration(double s) {
  char buf[32];
  const long t = static_cast<long>(s + 0.5);
  if (t >= 3600) {
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, t / 60 % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  }
  return buf;
}

// On a terminal one line redrawn in place; otherwise one line per evaluation (CI logs).
void DrawProgress(const tune::Progress& p) {
  static const bool tty = isatty(fileno(stderr)) != 0;
  constexpr int kWidth = 30;
  const int filled = p.budget > 0 ? kWidth * p.done / p.budget : kWidth;
  std::string bar(filled, '#');
  bar.append(kWidth - filled, '.');
  std::fprintf(stderr, "%stune [%s] %d/%d evals  best %.4g  elapsed %s  remaining %s%s%s",
               tty ? "\r" : "", bar.c_str(), p.done, p.budget, p.best,
               Duration(p.elapsed_s).c_str(), Duration(p.remaining_s).c_str(),
               p.replayed > 0 ? ("  (" + std::to_string(p.replayed) + " from log)").c_str() : "",
               tty ? "" : "\n");
  if (tty && p.done == p.budget) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

int RunTune(const TuneArgs& args) {
  // MPI starts only here, and only under mpirun: every other command is a plain process.
  tune::Cluster cluster;
  const bool root = cluster.rank() == 0;
  auto fail = [&](const std::string& message) {
    std::fprintf(stderr, "frenetic tune%s: %s\n",
                 root ? "" : (" (rank " + std::to_string(cluster.rank()) + ")").c_str(),
                 message.c_str());
    return 1;
  };

  auto suite = tune::LoadSuite(args.suite);
  std::unique_ptr<tune::Evaluator> evaluator;
  std::string error;
  if (!suite.ok()) {
    error = suite.message();
  } else {
    if (!args.map.empty()) suite->map_path = args.map;  // unused by a CommonRoad suite
    if (args.budget < 0 || args.jobs < 0) {
      error = "--budget and --jobs must be >= 0";
    } else {
      auto created = tune::Evaluator::Create(*suite, args.jobs, cluster);
      if (created.ok()) {
        evaluator = std::move(*created);
      } else {
        error = created.message();
      }
    }
  }
  // Every rank must agree that set-up worked before any rank waits for another.
  std::vector<double> failed{error.empty() ? 0.0 : 1.0};
  cluster.SumToRoot(&failed);
  cluster.Broadcast(&failed);
  if (!error.empty()) return fail(error);
  if (failed[0] > 0) return 1;  // another rank said why

  if (!root) {
    if (Status s = evaluator->Serve(); !s.ok()) return fail(s.message());
    return 0;
  }

  tune::TuneOptions options;
  options.budget = args.budget;
  options.resume_path = args.resume;
  options.log_path = args.log.empty() ? args.resume : args.log;
  options.progress = DrawProgress;
  const auto t0 = std::chrono::steady_clock::now();
  auto result = tune::Tune(*suite, options, *evaluator);
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!result.ok()) return fail(result.message());

  if (!args.output.empty()) {
    std::ofstream out(args.output);
    out << "# Tuned by `frenetic tune --suite " << args.suite << "` (" << result->evaluations
        << " evaluations)\n"
        << result->tuned_yaml;
    if (!out) return fail(args.output + ": cannot write the tuned config");
  }
  if (args.json) {
    nlohmann::json j = result->ToJson();
    j["suite"] = args.suite;
    j["ranks"] = cluster.size();
    j["wall_s"] = wall_s;
    j["output"] = args.output;
    j["tuned_config"] = result->tuned_yaml;
    std::printf("%s\n", JsonText(j).c_str());
  } else {
    std::printf("%s", result->ToTable().c_str());
    std::printf("wall time %.1f s on %d rank(s)\n", wall_s, cluster.size());
    if (args.output.empty()) {
      std::fprintf(stderr, "frenetic tune: use -o FILE.yaml to save the tuned config\n");
    } else {
      // A CommonRoad suite's config already has config/commonroad.yaml in it: loaded with
      // --config, that file would be laid over it again.
      std::printf("tuned config written to %s (load it with %s)\n", args.output.c_str(),
                  suite->kind == tune::SuiteKind::kCommonRoad
                      ? "frenetic commonroad --commonroad-config"
                      : "--config");
    }
  }
  return 0;
}

}  // namespace

void RegisterTune(CLI::App& app) {
  auto args = std::make_shared<TuneArgs>();
  auto* sub = app.add_subcommand(
      "tune", "Search planner cost weights on a seeded scenario suite (threads and MPI ranks)");
  sub->add_option("--suite", args->suite,
                  "Suite file, e.g. config/tune/default.yaml (Udacity scenarios and seeds) or "
                  "config/tune/commonroad.yaml (a directory of CommonRoad scenarios)")
      ->required();
  sub->add_option("-o,--output", args->output, "Write the tuned planner config (YAML) here");
  sub->add_option("--map", args->map, "Track file (overrides the suite's map)");
  sub->add_option("--budget", args->budget, "Search evaluations (default: the suite's budget)");
  sub->add_option("--jobs", args->jobs,
                  "Threads per process (default: every core this process may use, its CPU "
                  "affinity: taskset)");
  sub->add_option("--resume", args->resume,
                  "Continue from this JSON-lines log (also the log unless --log is given)");
  sub->add_option("--log", args->log, "Append every evaluation to this JSON-lines log");
  sub->add_flag("--json", args->json, "Print the result as one JSON object");
  sub->callback([args] { ExitWith(RunTune(*args)); });
}

}  // namespace frenetic::apps
