#include "frenetic/record/plan_json.h"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "frenetic/json_text.h"

namespace frenetic::record {
namespace {

const char* StatusName(plan::PlanStatus s) {
  switch (s) {
    case plan::PlanStatus::kOk: return "ok";
    case plan::PlanStatus::kFallbackUsed: return "fallback";
    case plan::PlanStatus::kInvalidInput: return "invalid_input";
    case plan::PlanStatus::kOverBudget: return "over_budget";
  }
  return "?";
}

nlohmann::json Costs(const std::vector<plan::CostTermValue>& terms) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& t : terms) {
    a.push_back(
        {{"name", t.name}, {"weight", FiniteOrNull(t.weight)}, {"value", FiniteOrNull(t.value)}});
  }
  return a;
}

nlohmann::json Node(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Map: {
      nlohmann::json o = nlohmann::json::object();
      for (const auto& kv : n) o[kv.first.as<std::string>()] = Node(kv.second);
      return o;
    }
    case YAML::NodeType::Sequence: {
      nlohmann::json a = nlohmann::json::array();
      for (const auto& e : n) a.push_back(Node(e));
      return a;
    }
    case YAML::NodeType::Scalar: {
      const std::string v = n.Scalar();
      if (n.Tag() != "!") {  // unquoted: a number or a boolean when it parses as one
        if (v == "true" || v == "True") return true;
        if (v == "false" || v == "False") return false;
        char* end = nullptr;
        errno = 0;
        const double d = std::strtod(v.c_str(), &end);
        if (!v.empty() && end == v.c_str() + v.size() && errno == 0 && std::isfinite(d)) {
          if (d == std::floor(d) && std::abs(d) < 1e15 && v.find_first_of(".eE") == v.npos) {
            return static_cast<long long>(d);
          }
          return d;
        }
      }
      return v;
    }
    default: return nullptr;
  }
}

// A candidate's coordinates at 0.1 m, the value `frenetic report` draws: the text such a value
// prints as ("1234.5") is the page's own rounding, so the page comes out the same from the
// record (non-finite values stay null).
nlohmann::json Decimeters(const std::vector<double>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (double e : v) {
    if (!std::isfinite(e)) {
      a.push_back(e);
      continue;
    }
    char buf[64];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, e, std::chars_format::fixed, 1);
    double rounded = e;
    if (ec == std::errc()) std::from_chars(buf, end, rounded);
    a.push_back(rounded);
  }
  return a;
}

}  // namespace

nlohmann::json PlanJson(plan::PlanStatus status, const plan::PlanSummary& s, double plan_ms,
                        double time_scale, const std::vector<plan::CandidateTrace>& candidates) {
  const double k = time_scale;
  nlohmann::json rejections = nlohmann::json::object();
  for (int r = 0; r < static_cast<int>(plan::Reject::kCount); ++r) {
    rejections[plan::ToString(static_cast<plan::Reject>(r))] = s.rejections[r];
  }
  nlohmann::json traced = nlohmann::json::array();
  for (const plan::CandidateTrace& c : candidates) {
    nlohmann::json reject = nullptr;
    if (c.reject >= 0 && c.reject < static_cast<int>(plan::Reject::kCount)) {
      reject = plan::ToString(static_cast<plan::Reject>(c.reject));
    }
    traced.push_back({{"lane", c.lane},
                      {"end_speed", FiniteOrNull(c.end_speed)},
                      {"duration", FiniteOrNull(c.duration)},
                      {"total_cost", FiniteOrNull(c.total_cost)},
                      {"checked", c.checked},
                      {"winner", c.winner},
                      {"reject", reject},
                      {"reject_car", c.reject_car >= 0 ? nlohmann::json(c.reject_car)
                                                       : nlohmann::json(nullptr)},
                      {"reject_t", FiniteOrNull(c.reject_time)},
                      {"x", Decimeters(c.x)},
                      {"y", Decimeters(c.y)},
                      {"costs", Costs(c.costs)}});
  }
  return {{"status", StatusName(status)},
          {"ms_total", k * plan_ms},
          {"ms_planner", k * s.ms_total},
          {"ms_stages",
           {{"prepare", k * s.ms_prepare},
            {"generate", k * s.ms_generate},
            {"score", k * s.ms_score},
            {"check", k * s.ms_check},
            {"refine", k * s.ms_refine},
            {"output", k * s.ms_output}}},
          {"candidates_generated", s.candidates_generated},
          {"candidates_scored", s.candidates_scored},
          {"candidates_checked", s.candidates_checked},
          {"candidates_feasible", s.candidates_feasible},
          {"rejections", rejections},
          {"winner_costs", Costs(s.winner_costs)},
          {"winner_total_cost", FiniteOrNull(s.winner_total_cost)},
          {"winner_lane", s.winner_lane},
          {"winner_end_speed", FiniteOrNull(s.winner_end_speed)},
          {"winner_duration", FiniteOrNull(s.winner_duration)},
          {"refine_iterations", s.refine_iterations},
          {"deadline_stage", plan::ToString(s.deadline_stage)},
          {"refine_cost_before", FiniteOrNull(s.refine_cost_before)},
          {"refine_cost_after", FiniteOrNull(s.refine_cost_after)},
          {"points_kept", s.points_kept},
          {"candidates", traced}};
}

nlohmann::json YamlToJson(const std::string& yaml_text) {
  try {
    return Node(YAML::Load(yaml_text));
  } catch (const YAML::Exception&) {
    return yaml_text;
  }
}

}  // namespace frenetic::record
