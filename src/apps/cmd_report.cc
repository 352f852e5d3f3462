// `frenetic report RUN.jsonl -o OUT.html`: the self-contained HTML report of a recorded drive.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "apps/commands.h"
#include "frenetic/json_text.h"
#include "frenetic/record/reader.h"
#include "frenetic/report/page.h"

namespace frenetic::apps {
namespace {

struct ReportArgs {
  std::string run;
  std::string output;
  record::ReadOptions read;
  bool json = false;
};

// RUN.jsonl (or RUN.jsonl.gz) -> RUN.html next to it.
std::string DefaultOutput(std::string run) {
  if (run.size() > 3 && run.compare(run.size() - 3, 3, ".gz") == 0) run.resize(run.size() - 3);
  const size_t slash = run.find_last_of('/');
  const size_t dot = run.find_last_of('.');
  const bool has_extension = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  return (has_extension ? run.substr(0, dot) : run) + ".html";
}

// A CommonRoad run's verdict (its footer's, commonroad/record.h) as "; solved, goal at step 78"
// or "; NOT solved: goal at step 50"; empty for a drive.
std::string Verdict(const record::RunData& run) {
  if (run.header.world != "commonroad" || !run.has_footer) return "";
  const nlohmann::json f = nlohmann::json::parse(run.footer_json, nullptr, false);
  if (!f.is_object() || !f.contains("solved") || !f["solved"].is_boolean()) return "";
  if (f["solved"].get<bool>()) {
    return "; solved, goal at step " +
           (f.contains("goal_step") ? f["goal_step"].dump() : std::string("?"));
  }
  std::string out = "; NOT solved:";
  if (f.contains("failures") && f["failures"].is_array()) {
    for (const nlohmann::json& e : f["failures"]) {
      if (!e.is_object()) continue;
      const bool named = e.contains("kind") && e["kind"].is_string();
      out += " " + (named ? e["kind"].get<std::string>() : std::string("?")) + " at step " +
             (e.contains("step") ? e["step"].dump() : std::string("?"));
    }
  }
  return out;
}

int RunReport(const ReportArgs& args) {
  auto run = record::ReadRecordFile(args.run, args.read);
  if (!run.ok()) {
    std::fprintf(stderr, "frenetic report: %s\n", run.message().c_str());
    return 1;
  }
  // Warnings go to stderr: stdout carries the result (and --json must stay parseable).
  std::shared_ptr<spdlog::logger> log = spdlog::get("report");
  if (!log) log = spdlog::stderr_color_mt("report");
  for (const std::string& warning : run->warnings) {
    log->warn("{}: {}", args.run, warning);
  }
  if (run->skipped_lines > static_cast<int>(run->warnings.size())) {
    log->warn("{}: {} malformed lines skipped in all", args.run, run->skipped_lines);
  }
  const std::string output = args.output.empty() ? DefaultOutput(args.run) : args.output;
  const std::string page = report::RenderPage(*run, args.run);
  if (Status status = report::WriteFile(output, page); !status.ok()) {
    std::fprintf(stderr, "frenetic report: %s\n", status.message().c_str());
    return 1;
  }
  if (args.json) {
    nlohmann::json out = {{"output", output},
                          {"bytes", page.size()},
                          {"exchanges", run->size()},
                          {"lines", run->lines},
                          {"skipped_lines", run->skipped_lines},
                          {"candidate_cycles", run->candidate_cycles.size()},
                          {"incidents", run->incidents.size()},
                          {"footer", run->has_footer},
                          {"sim_seconds", std::round((run->t.back() - run->t.front()) * 1000) / 1000}};
    std::printf("%s\n", JsonText(out).c_str());
  } else {
    std::printf("wrote %s (%.1f MB): %d exchanges over %.1f s, %zu cycles with candidates, "
                "%zu incidents, %d lines skipped%s%s\n",
                output.c_str(), page.size() / 1e6, run->size(), run->t.back() - run->t.front(),
                run->candidate_cycles.size(), run->incidents.size(), run->skipped_lines,
                run->has_footer ? "" : ", no footer (run cut short?)", Verdict(*run).c_str());
  }
  return 0;
}

}  // namespace

void RegisterReport(CLI::App& app) {
  auto args = std::make_shared<ReportArgs>();
  auto* sub = app.add_subcommand(
      "report",
      "Write a self-contained HTML report of a drive recorded with `frenetic drive --record`:\n"
      "a top-down replay with the cycle's candidates, plots of speed, acceleration, jerk, lane,\n"
      "gap, headway, planning time and cost terms over time, per-cycle cost tables and the\n"
      "drive's summary. The page works offline (everything is inlined).");
  sub->add_option("run", args->run,
                  "The record, JSON lines (header, exchanges, footer), plain or gzip-compressed")
      ->required();
  sub->add_option("-o,--output", args->output,
                  "The HTML file to write (default: RUN with the extension .html)");
  sub->add_option("--max-candidates", args->read.max_candidates,
                  "Candidates kept per cycle, best first; the winner is always kept (default: 8)")
      ->check(CLI::Range(1, 1000));
  sub->add_option("--candidate-cycles", args->read.max_candidate_cycles,
                  "Cycles whose candidates are kept, spread evenly over the run; incidents (and\n"
                  "the 5 cycles before each) and lane changes are kept on top (default: 1500)")
      ->check(CLI::Range(1, 1000000));
  sub->add_option("--path-stride", args->read.path_stride,
                  "Keep every Nth point of the path sent, 0.02 s apart (default: 5, i.e. 0.1 s)")
      ->check(CLI::Range(1, 1000));
  sub->add_option("--traffic-range", args->read.traffic_range,
                  "Traffic farther than this from the ego is left out of the replay, m "
                  "(default: 250)")
      ->check(CLI::PositiveNumber);
  sub->add_flag("--json", args->json,
                "Print what was written as one JSON object on stdout instead of a sentence");
  sub->callback([args] { ExitWith(RunReport(*args)); });
}

}  // namespace frenetic::apps
