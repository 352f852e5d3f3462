#include "frenetic/report/page.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "frenetic/check.h"
#include "frenetic/json_text.h"
#include "report/assets.h"

namespace frenetic::report {
namespace {

using record::Candidate;
using record::CandidateCost;
using record::CountColumn;
using record::CycleCandidates;
using record::Incident;
using record::RecordHeader;
using record::RunData;
using record::TermColumn;

constexpr std::string_view kDataPlaceholder = "@FRENETIC_DATA@";

// Appends compact JSON. Numbers are rounded here, once: the page's size (and so its opening
// time) is dominated by the per-exchange columns, and 17-digit doubles would triple it.
class JsonOut {
 public:
  std::string& str() { return out_; }

  JsonOut& Raw(std::string_view s) {
    out_ += s;
    return *this;
  }
  JsonOut& Key(std::string_view key) {
    Sep();
    out_ += JsonText(nlohmann::json(std::string(key)));
    out_ += ':';
    fresh_ = true;
    return *this;
  }
  JsonOut& Open(char c) {
    Sep();
    out_ += c;
    fresh_ = true;
    return *this;
  }
  JsonOut& Close(char c) {
    out_ += c;
    fresh_ = false;
    return *this;
  }
  JsonOut& String(std::string_view s) {
    Sep();
    out_ += JsonText(nlohmann::json(std::string(s)));
    return *this;
  }
  JsonOut& Json(std::string_view raw) {  // an already serialised JSON value
    Sep();
    out_ += raw;
    return *this;
  }
  // `decimals` digits after the point, trailing zeros dropped; NaN and infinities are null.
  JsonOut& Fixed(double v, int decimals) {
    Sep();
    if (!std::isfinite(v)) {
      out_ += "null";
      return *this;
    }
    char buf[64];
    auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v, std::chars_format::fixed, decimals);
    if (ec != std::errc()) {  // beyond 64 characters: not a value worth plotting
      out_ += "null";
      return *this;
    }
    std::string_view text(buf, end - buf);
    if (text.find('.') != std::string_view::npos) {
      while (text.back() == '0') text.remove_suffix(1);
      if (text.back() == '.') text.remove_suffix(1);
    }
    if (text == "-0") text = "0";
    out_ += text;
    return *this;
  }
  // Four significant digits, for costs whose scale is unknown.
  JsonOut& Significant(double v) {
    Sep();
    if (!std::isfinite(v)) {
      out_ += "null";
      return *this;
    }
    char buf[64];
    auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v, std::chars_format::general, 4);
    out_.append(buf, ec == std::errc() ? end : buf);
    return *this;
  }
  JsonOut& Int(long long v) {
    Sep();
    out_ += std::to_string(v);
    return *this;
  }
  JsonOut& Fixeds(const std::vector<double>& v, int decimals) {
    Open('[');
    for (double x : v) Fixed(x, decimals);
    return Close(']');
  }
  JsonOut& Significants(const std::vector<double>& v) {
    Open('[');
    for (double x : v) Significant(x);
    return Close(']');
  }
  JsonOut& Ints(const std::vector<int>& v) {
    Open('[');
    for (int x : v) Int(x);
    return Close(']');
  }

 private:
  void Sep() {
    if (!fresh_ && !out_.empty() && out_.back() != ':') out_ += ',';
    fresh_ = false;
  }
  std::string out_;
  bool fresh_ = true;
};

// A weight column is nearly always constant over a run: then one number stands for it.
void WriteWeights(JsonOut& o, const std::vector<double>& w) {
  double first = std::nan("");
  bool constant = true;
  for (double v : w) {
    if (!std::isfinite(v)) continue;
    if (!std::isfinite(first)) first = v;
    constant = constant && v == first;
  }
  if (constant) {
    o.Significant(first);
  } else {
    o.Significants(w);
  }
}

}  // namespace

std::string PageDataJson(const RunData& run, std::string_view source) {
  JsonOut o;
  o.Open('{');
  o.Key("format").String("frenetic-report");
  o.Key("version").Int(1);
  o.Key("source").String(source);
  o.Key("generator").String(std::string("frenetic ") + FRENETIC_VERSION);

  const RecordHeader& h = run.header;
  o.Key("header").Open('{');
  o.Key("version").Int(h.version);
  o.Key("map").String(h.map);
  o.Key("scenario").String(h.scenario);
  o.Key("planner").String(h.planner);
  o.Key("seed").Int(h.seed);
  o.Key("max_s").Fixed(h.max_s, 3);
  o.Key("lane_width").Fixed(h.lane_width, 3);
  o.Key("lanes").Int(h.lanes);
  o.Key("car_length").Fixed(h.car_length, 3);
  o.Key("car_width").Fixed(h.car_width, 3);
  o.Key("config").Json(h.config_json);
  // A CommonRoad run's fields (world "commonroad" switches the page's script to its parts); a
  // drive's data has none of them (and stays as it was).
  if (!h.world.empty()) {
    o.Key("world").String(h.world);
    o.Key("problem").Int(h.problem);
    o.Key("dt").Fixed(h.dt, 4);
    o.Key("prediction").String(h.prediction);
    o.Key("vehicle").String(h.vehicle);
  }
  o.Close('}');
  o.Key("center").Open('{');
  o.Key("x").Fixeds(h.center_x, 2);
  o.Key("y").Fixeds(h.center_y, 2);
  o.Close('}');
  if (!h.road_lanes.empty()) {
    o.Key("road").Open('[');
    for (const RecordHeader::Lane& l : h.road_lanes) {
      o.Open('{');
      o.Key("lx").Fixeds(l.left.x, 2).Key("ly").Fixeds(l.left.y, 2);
      o.Key("rx").Fixeds(l.right.x, 2).Key("ry").Fixeds(l.right.y, 2);
      o.Close('}');
    }
    o.Close(']');
  }
  if (!h.goals.empty()) {
    o.Key("goals").Open('[');
    for (const RecordHeader::Goal& g : h.goals) {
      o.Open('{').Key("x").Fixeds(g.outline.x, 2).Key("y").Fixeds(g.outline.y, 2);
      o.Key("steps");
      if (g.step_lo >= 0) {
        o.Open('[').Int(g.step_lo).Int(g.step_hi).Close(']');
      } else {
        o.Json("null");
      }
      o.Close('}');
    }
    o.Close(']');
  }

  o.Key("n").Int(run.size());
  o.Key("ex").Open('{');
  o.Key("i").Ints(run.cycle);
  o.Key("t").Fixeds(run.t, 3);
  o.Key("x").Fixeds(run.x, 2);
  o.Key("y").Fixeds(run.y, 2);
  o.Key("yaw").Fixeds(run.yaw_deg, 1);
  o.Key("speed").Fixeds(run.speed_mph, 2);
  o.Key("s").Fixeds(run.s, 1);
  o.Key("d").Fixeds(run.d, 2);
  o.Key("acc").Fixeds(run.acc, 2);
  o.Key("jerk").Fixeds(run.jerk, 2);
  o.Key("gap").Fixeds(run.gap, 1);
  o.Key("headway").Fixeds(run.headway, 2);
  o.Key("lane").Ints(run.lane);
  o.Key("ms").Fixeds(run.ms_total, 3);
  o.Key("cost").Significants(run.winner_total_cost);
  o.Key("refine_before").Significants(run.refine_cost_before);
  o.Key("refine_after").Significants(run.refine_cost_after);
  o.Key("refine_iterations").Ints(run.refine_iterations);
  o.Key("winner_lane").Ints(run.winner_lane);
  o.Key("generated").Ints(run.generated);
  o.Key("scored").Ints(run.scored);
  o.Key("checked").Ints(run.checked);
  o.Key("feasible").Ints(run.feasible);
  o.Key("status").Ints(run.status);
  o.Close('}');
  o.Key("status_names").Open('[');
  for (const std::string& s : run.status_names) o.String(s);
  o.Close(']');
  o.Key("rejections").Open('[');
  for (const CountColumn& c : run.rejections) {
    o.Open('{').Key("name").String(c.name).Key("count").Ints(c.count).Close('}');
  }
  o.Close(']');
  o.Key("terms").Open('[');
  for (const TermColumn& c : run.terms) {
    o.Open('{').Key("name").String(c.name).Key("weight");
    WriteWeights(o, c.weight);
    o.Key("value").Significants(c.value).Close('}');
  }
  o.Close(']');

  o.Key("path").Open('{');
  o.Key("off").Ints(run.path_offset);
  o.Key("x").Fixeds(run.path_x, 1);
  o.Key("y").Fixeds(run.path_y, 1);
  o.Close('}');
  o.Key("traffic").Open('{');
  o.Key("off").Ints(run.traffic_offset);
  o.Key("id").Ints(run.traffic_id);
  o.Key("x").Fixeds(run.traffic_x, 1);
  o.Key("y").Fixeds(run.traffic_y, 1);
  o.Key("h").Fixeds(run.traffic_heading_deg, 0);
  bool sizes = false;
  for (double v : run.traffic_length) sizes = sizes || std::isfinite(v);
  if (sizes) {  // cars of their own sizes (CommonRoad); a drive's cars are all the header's
    o.Key("l").Fixeds(run.traffic_length, 2);
    o.Key("w").Fixeds(run.traffic_width, 2);
  }
  o.Close('}');

  // Candidates: [lane, end_speed, duration, total_cost, flags (1 checked, 2 winner), reject or
  // null, [x...], [y...], [term, weight, value, term, weight, value, ...]].
  o.Key("candidates").Open('[');
  for (const CycleCandidates& cycle : run.candidate_cycles) {
    o.Open('{').Key("e").Int(cycle.exchange).Key("listed").Int(cycle.listed).Key("c").Open('[');
    for (const Candidate& c : cycle.candidates) {
      o.Open('[').Int(c.lane).Fixed(c.end_speed, 2).Fixed(c.duration, 2).Significant(c.total_cost);
      o.Int((c.checked ? 1 : 0) | (c.winner ? 2 : 0));
      if (c.reject.empty()) {
        o.Json("null");
      } else {
        o.String(c.reject);
      }
      o.Fixeds(c.x, 1).Fixeds(c.y, 1).Open('[');
      for (const CandidateCost& k : c.costs) o.Int(k.term).Significant(k.weight).Significant(k.value);
      o.Close(']').Close(']');
    }
    o.Close(']').Close('}');
  }
  o.Close(']');

  o.Key("incidents").Open('[');
  for (const Incident& i : run.incidents) {
    o.Open('{').Key("e").Int(i.exchange).Key("t").Fixed(i.t, 3).Key("s").Fixed(i.s, 1);
    o.Key("d").Fixed(i.d, 2).Key("lane").Int(i.lane).Key("kind").String(i.kind);
    o.Key("value").Significant(i.value).Close('}');
  }
  o.Close(']');
  o.Key("footer").Json(run.has_footer ? run.footer_json : "null");
  o.Key("reading").Open('{');
  o.Key("lines").Int(run.lines).Key("skipped").Int(run.skipped_lines).Key("warnings").Open('[');
  for (const std::string& w : run.warnings) o.String(w);
  o.Close(']').Close('}');
  o.Close('}');
  return std::move(o.str());
}

std::string_view PageTemplate() { return internal::PageTemplateText(); }

std::string RenderPage(const RunData& run, std::string_view source) {
  std::string data = PageDataJson(run, source);
  // '<' occurs only inside JSON strings, where \u003c means the same: no "</script>" or "<!--"
  // in a string can end the data block early.
  std::string escaped;
  escaped.reserve(data.size() + 64);
  for (char c : data) {
    if (c == '<') {
      escaped += "\\u003c";
    } else {
      escaped += c;
    }
  }
  const std::string_view page = PageTemplate();
  const size_t at = page.find(kDataPlaceholder);
  FRENETIC_CHECK(at != std::string_view::npos);  // report.cmake refuses a template without it
  std::string out;
  out.reserve(page.size() + escaped.size());
  out += page.substr(0, at);
  out += escaped;
  out += page.substr(at + kDataPlaceholder.size());
  return out;
}

Status WriteFile(const std::string& path, std::string_view content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return Status::Error(path + ": cannot open for writing");
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  out.close();
  if (!out) return Status::Error(path + ": write failed");
  return Status::Ok();
}

}  // namespace frenetic::report
