#include "apps/commonroad_summary.h"

#include <algorithm>
#include <cstdio>
#include <set>

namespace frenetic::apps::commonroad_cli {

using nlohmann::json;

namespace {

double Max(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

std::string Format(const char* format, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), format, args...);
  return buf;
}

}  // namespace

Summary Summarise(const std::vector<FileReport>& files) {
  Summary s;
  for (const FileReport& f : files) {
    if (!f.error.empty()) {
      ++s.unreadable_files;
      continue;
    }
    for (const ProblemReport& p : f.problems) {
      ++s.problems;
      s.solved += p.verdict.solved;
      if (!p.road_error.empty()) ++s.failures["road"];
      std::set<std::string> kinds;
      for (const cr::Failure& fl : p.verdict.failures) kinds.insert(cr::ToString(fl.kind));
      for (const std::string& k : kinds) ++s.failures[k];
      s.plan_ms.insert(s.plan_ms.end(), p.plan_ms.begin(), p.plan_ms.end());
      s.candidates += p.candidates;
    }
  }
  return s;
}

json SummaryJson(const Summary& s, const SummarySettings& settings) {
  const size_t cycles = s.plan_ms.size();
  return {{"prediction", settings.prediction},
          {"vehicle", "KS" + std::to_string(settings.vehicle_type)},
          {"problems", s.problems},
          {"solved", s.solved},
          {"unreadable_files", s.unreadable_files},
          {"failures", s.failures},
          {"cycles", static_cast<int>(cycles)},
          {"plan_ms",
           {{"p50", Percentile(s.plan_ms, 0.5)},
            {"p99", Percentile(s.plan_ms, 0.99)},
            {"max", Max(s.plan_ms)}}},
          {"candidates_mean", cycles ? s.candidates / cycles : 0.0}};
}

std::string SummaryText(const Summary& s, const SummarySettings& settings) {
  const size_t cycles = s.plan_ms.size();
  std::string text = Format("\nsolved %d / %d problems (%s predictions, KS%d)", s.solved,
                            s.problems, settings.prediction.c_str(), settings.vehicle_type);
  if (s.unreadable_files > 0) text += Format(", %d file(s) unreadable", s.unreadable_files);
  text += "\n";
  if (!s.failures.empty()) {
    text += "failures:";
    for (const auto& [k, v] : s.failures) text += Format(" %s %d", k.c_str(), v);
    text += "\n";
  }
  text += Format("planning per cycle: p50 %.2f ms, p99 %.2f ms, max %.2f ms over %d cycles\n",
                 Percentile(s.plan_ms, 0.5), Percentile(s.plan_ms, 0.99), Max(s.plan_ms),
                 static_cast<int>(cycles));
  text += Format("candidates per cycle: mean %.0f\n", cycles ? s.candidates / cycles : 0.0);
  return text;
}

}  // namespace frenetic::apps::commonroad_cli
