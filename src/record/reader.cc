#include "frenetic/record/reader.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <utility>

#include "frenetic/record/schema.h"
#include "record/candidate_sampler.h"
#include "record/gzip_stream.h"

namespace frenetic::record {
namespace {

using json = nlohmann::json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A candidate's path is drawn as a polyline; more points than this add bytes, not insight.
constexpr int kMaxCandidatePoints = 40;

// Field access that never throws: a missing key or a value of the wrong type gives the fallback.
const json* Field(const json& o, const char* key) {
  if (!o.is_object()) return nullptr;
  auto it = o.find(key);
  return it == o.end() ? nullptr : &*it;
}
double Num(const json& o, const char* key, double fallback = kNaN) {
  const json* f = Field(o, key);
  return f != nullptr && f->is_number() ? f->get<double>() : fallback;
}
int Int(const json& o, const char* key, int fallback) {
  const double v = Num(o, key);
  return std::isfinite(v) && std::abs(v) < 1e9 ? static_cast<int>(std::lround(v)) : fallback;
}
std::string Str(const json& o, const char* key, std::string fallback = "") {
  const json* f = Field(o, key);
  if (f == nullptr) return fallback;
  if (f->is_string()) return f->get<std::string>();
  if (f->is_number()) return f->dump();
  return fallback;
}
// A numeric array as doubles; non-numbers become NaN.
std::vector<double> Numbers(const json* a) {
  std::vector<double> out;
  if (a == nullptr || !a->is_array()) return out;
  out.reserve(a->size());
  for (const json& v : *a) out.push_back(v.is_number() ? v.get<double>() : kNaN);
  return out;
}

class Reader {
 public:
  Reader(std::string_view source, const ReadOptions& options, const GzipStreambuf* gzip)
      : source_(source), options_(options), gzip_(gzip), sampler_(options.max_candidate_cycles) {}

  StatusOr<RunData> Read(std::istream& in) {
    std::string line;
    int line_number = 0;
    while (std::getline(in, line)) {
      ++line_number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.find_first_not_of(" \t") == std::string::npos) continue;
      ++run_.lines;
      json record = json::parse(line, nullptr, /*allow_exceptions=*/false);
      if (record.is_discarded() || !record.is_object()) {
        Skip(line_number, "not a JSON object");
        continue;
      }
      const std::string type = Str(record, key::kType);
      if (!have_header_) {
        if (type != key::kHeader) {
          if (type.empty()) {
            Skip(line_number, "no \"type\"");
            continue;
          }
          return Status::Error(std::string(source_) + ":" + std::to_string(line_number) +
                               ": record has no header (first record is of type \"" + type +
                               "\")");
        }
        Status status = ReadHeader(record);
        if (!status.ok()) {
          return Status::Error(std::string(source_) + ":" + std::to_string(line_number) +
                               ": header: " + status.message());
        }
        have_header_ = true;
      } else if (type == key::kExchange) {
        std::string why = ReadExchange(record);
        if (!why.empty()) Skip(line_number, why);
      } else if (type == key::kFooter) {
        const json* report = Field(record, key::kReport);
        run_.has_footer = true;
        run_.footer_json = report != nullptr ? report->dump() : "null";
      } else if (type == key::kHeader) {
        Skip(line_number, "a second header");
      } else {
        Skip(line_number, "unknown type \"" + type + "\"");
      }
    }
    if (in.bad()) return Status::Error(std::string(source_) + ": read error");
    const std::string gzip_error = gzip_ != nullptr ? gzip_->error() : std::string();
    if (!gzip_error.empty()) {
      if (!have_header_ || run_.size() == 0) {
        return Status::Error(std::string(source_) + ": " + gzip_error);
      }
      // What was read stays usable, as a record without its last lines.
      run_.warnings.push_back("after line " + std::to_string(line_number) + ": " + gzip_error);
    }
    if (!have_header_) return Status::Error(std::string(source_) + ": record has no header line");
    if (run_.size() == 0) return Status::Error(std::string(source_) + ": no usable exchange");
    run_.candidate_cycles = sampler_.Take();
    run_.path_offset.push_back(static_cast<int>(run_.path_x.size()));
    run_.traffic_offset.push_back(static_cast<int>(run_.traffic_id.size()));
    return std::move(run_);
  }

 private:
  void Skip(int line_number, const std::string& why) {
    ++run_.skipped_lines;
    if (static_cast<int>(run_.warnings.size()) < options_.max_warnings) {
      run_.warnings.push_back("line " + std::to_string(line_number) + ": " + why + "; skipped");
    }
  }

  Status ReadHeader(const json& h) {
    RecordHeader& header = run_.header;
    header.version = Int(h, key::kVersion, 0);
    header.map = Str(h, key::kMap);
    header.scenario = Str(h, key::kScenario);
    header.planner = Str(h, key::kPlanner);
    const double seed = Num(h, key::kSeed, 0);
    header.seed = std::isfinite(seed) ? static_cast<std::int64_t>(seed) : 0;
    header.max_s = Num(h, key::kMaxS, 0);
    header.lane_width = Num(h, key::kLaneWidth, 4.0);
    header.lanes = Int(h, key::kLanes, 3);
    header.car_length = Num(h, key::kCarLength, 4.6);
    header.car_width = Num(h, key::kCarWidth, 2.4);
    if (!(header.lane_width > 0 && header.lane_width < 100)) {
      return Status::Error("lane_width must be in (0, 100) m");
    }
    if (header.lanes < 1 || header.lanes > 16) return Status::Error("lanes must be in [1, 16]");
    if (!(header.car_length > 0 && header.car_width > 0)) {
      return Status::Error("car_length and car_width must be > 0");
    }
    if (const json* c = Field(h, key::kCenterline); c != nullptr && c->is_array()) {
      for (const json& p : *c) {
        if (p.is_array() && p.size() >= 2 && p[0].is_number() && p[1].is_number()) {
          header.center_x.push_back(p[0].get<double>());
          header.center_y.push_back(p[1].get<double>());
        }
      }
    }
    if (const json* config = Field(h, key::kConfig); config != nullptr) {
      header.config_json = config->dump();
    }
    header.world = Str(h, key::kWorld);
    if (header.world.empty()) return Status::Ok();
    header.problem = Int(h, key::kProblem, -1);
    header.dt = Num(h, key::kDt, 0);
    header.prediction = Str(h, key::kPrediction);
    header.vehicle = Str(h, key::kVehicle);
    if (const json* road = Field(h, key::kRoad); road != nullptr) {
      if (const json* lanes = Field(*road, key::kLanes); lanes != nullptr && lanes->is_array()) {
        for (const json& l : *lanes) {
          RecordHeader::Lane lane;
          lane.left = ReadPolyline(Field(l, key::kLeft));
          lane.right = ReadPolyline(Field(l, key::kRight));
          header.road_lanes.push_back(std::move(lane));
        }
      }
    }
    if (const json* goals = Field(h, key::kGoals); goals != nullptr && goals->is_array()) {
      for (const json& g : *goals) {
        RecordHeader::Goal goal;
        goal.outline = ReadPolyline(&g);
        if (const json* steps = Field(g, key::kSteps);
            steps != nullptr && steps->is_array() && steps->size() == 2 &&
            (*steps)[0].is_number_integer() && (*steps)[1].is_number_integer()) {
          goal.step_lo = (*steps)[0].get<int>();
          goal.step_hi = (*steps)[1].get<int>();
        }
        if (!goal.outline.x.empty()) header.goals.push_back(std::move(goal));
      }
    }
    return Status::Ok();
  }

  // {"x": [...], "y": [...]}: the points where both are finite numbers.
  static Polyline ReadPolyline(const json* o) {
    Polyline p;
    if (o == nullptr) return p;
    const std::vector<double> x = Numbers(Field(*o, "x")), y = Numbers(Field(*o, "y"));
    for (size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
      if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
      p.x.push_back(x[i]);
      p.y.push_back(y[i]);
    }
    return p;
  }

  int StatusIndex(const std::string& name) {
    auto& names = run_.status_names;
    auto it = std::find(names.begin(), names.end(), name);
    if (it != names.end()) return static_cast<int>(it - names.begin());
    names.push_back(name);
    return static_cast<int>(names.size()) - 1;
  }

  // The column for a term or reason, created on first sight and back-filled so every column
  // stays as long as the exchange columns.
  int TermIndex(const std::string& name) {
    for (size_t i = 0; i < run_.terms.size(); ++i) {
      if (run_.terms[i].name == name) return static_cast<int>(i);
    }
    TermColumn column;
    column.name = name;
    column.weight.assign(run_.t.size(), kNaN);
    column.value.assign(run_.t.size(), kNaN);
    run_.terms.push_back(std::move(column));
    return static_cast<int>(run_.terms.size()) - 1;
  }
  CountColumn& Rejection(const std::string& name) {
    for (CountColumn& c : run_.rejections) {
      if (c.name == name) return c;
    }
    run_.rejections.push_back({name, std::vector<int>(run_.t.size(), 0)});
    return run_.rejections.back();
  }

  // Returns why the exchange is unusable, or an empty string once it has been added.
  std::string ReadExchange(const json& e) {
    const json* tel = Field(e, key::kTelemetry);
    if (tel == nullptr || !tel->is_object()) return "exchange without \"telemetry\"";
    const double x = Num(*tel, "x"), y = Num(*tel, "y");
    if (!std::isfinite(x) || !std::isfinite(y)) return "telemetry.x or telemetry.y missing";
    const double t = Num(e, key::kTime);
    if (!std::isfinite(t)) return "exchange without a numeric \"t\"";

    const int k = run_.size();  // the row being added
    run_.cycle.push_back(Int(e, key::kCycle, k));
    run_.t.push_back(t);
    run_.x.push_back(x);
    run_.y.push_back(y);
    run_.yaw_deg.push_back(Num(*tel, "yaw", 0));
    run_.speed_mph.push_back(Num(*tel, "speed"));
    run_.s.push_back(Num(*tel, "s"));
    const double d = Num(*tel, "d");
    run_.d.push_back(d);

    static const json kEmpty = json::object();
    const json* metrics = Field(e, key::kMetrics);
    const json& m = metrics != nullptr ? *metrics : kEmpty;
    run_.acc.push_back(Num(m, "acc"));
    run_.jerk.push_back(Num(m, "jerk"));
    run_.gap.push_back(Num(m, "gap"));
    run_.headway.push_back(Num(m, "headway"));
    int lane = Int(m, "lane", -1);
    if (Field(m, "lane") == nullptr && std::isfinite(d) && d >= 0 &&
        d < run_.header.lanes * run_.header.lane_width) {
      lane = static_cast<int>(d / run_.header.lane_width);
    }
    run_.lane.push_back(lane);

    const json* plan = Field(e, key::kPlan);
    const json& p = plan != nullptr ? *plan : kEmpty;
    run_.ms_total.push_back(Num(p, "ms_total"));
    run_.winner_total_cost.push_back(Num(p, "winner_total_cost"));
    run_.refine_cost_before.push_back(Num(p, "refine_cost_before"));
    run_.refine_cost_after.push_back(Num(p, "refine_cost_after"));
    run_.winner_lane.push_back(Int(p, "winner_lane", -1));
    run_.generated.push_back(Int(p, "candidates_generated", -1));
    run_.scored.push_back(Int(p, "candidates_scored", -1));
    run_.checked.push_back(Int(p, "candidates_checked", -1));
    run_.feasible.push_back(Int(p, "candidates_feasible", -1));
    run_.refine_iterations.push_back(Int(p, "refine_iterations", -1));
    const std::string status = Str(p, "status");
    run_.status.push_back(status.empty() ? -1 : StatusIndex(status));

    for (CountColumn& c : run_.rejections) c.count.push_back(0);
    if (const json* r = Field(p, "rejections"); r != nullptr && r->is_object()) {
      for (const auto& [reason, count] : r->items()) {
        if (count.is_number()) Rejection(reason).count.resize(k + 1, 0);
        if (count.is_number()) Rejection(reason).count[k] = count.get<int>();
      }
    }
    for (TermColumn& c : run_.terms) {
      c.weight.push_back(kNaN);
      c.value.push_back(kNaN);
    }
    if (const json* costs = Field(p, "winner_costs"); costs != nullptr && costs->is_array()) {
      for (const json& c : *costs) {
        const std::string name = Str(c, "name");
        if (name.empty()) continue;
        const int ti = TermIndex(name);
        run_.terms[ti].weight.resize(k + 1, kNaN);
        run_.terms[ti].value.resize(k + 1, kNaN);
        run_.terms[ti].weight[k] = Num(c, "weight");
        run_.terms[ti].value[k] = Num(c, "value");
      }
    }

    ReadPath(Field(e, key::kPath));
    ReadTraffic(Field(*tel, key::kSensorFusion), x, y);
    ReadIncidents(Field(e, key::kIncidents), k);
    ReadCandidates(Field(p, "candidates"), k);
    return "";
  }

  void ReadPath(const json* path) {
    run_.path_offset.push_back(static_cast<int>(run_.path_x.size()));
    if (path == nullptr) return;
    const std::vector<double> px = Numbers(Field(*path, "x"));
    const std::vector<double> py = Numbers(Field(*path, "y"));
    const size_t n = std::min(px.size(), py.size());
    const size_t stride = static_cast<size_t>(options_.path_stride);
    for (size_t i = 0; i < n; ++i) {
      if (i % stride != 0 && i + 1 != n) continue;
      if (!std::isfinite(px[i]) || !std::isfinite(py[i])) continue;
      run_.path_x.push_back(px[i]);
      run_.path_y.push_back(py[i]);
    }
  }

  void ReadTraffic(const json* cars, double ego_x, double ego_y) {
    run_.traffic_offset.push_back(static_cast<int>(run_.traffic_id.size()));
    if (cars == nullptr || !cars->is_array()) return;
    for (const json& car : *cars) {
      if (!car.is_array() || car.size() < 5) continue;
      bool numeric = true;
      for (size_t i = 0; i < 5; ++i) numeric = numeric && car[i].is_number();
      if (!numeric) continue;
      const double cx = car[1].get<double>(), cy = car[2].get<double>();
      const double vx = car[3].get<double>(), vy = car[4].get<double>();
      if (std::abs(car[0].get<double>()) > 1e9) continue;
      if (!(std::hypot(cx - ego_x, cy - ego_y) <= options_.traffic_range)) continue;
      run_.traffic_id.push_back(static_cast<int>(car[0].get<double>()));
      run_.traffic_x.push_back(cx);
      run_.traffic_y.push_back(cy);
      // A standing car has no heading of its own; the page then draws it along the road.
      double heading = std::hypot(vx, vy) > 0.1 ? std::atan2(vy, vx) * 180.0 / std::numbers::pi
                                                : kNaN;
      double length = kNaN, width = kNaN;
      if (car.size() >= 9 && car[7].is_number() && car[8].is_number()) {
        length = car[7].get<double>();
        width = car[8].get<double>();
        if (!(length > 0 && width > 0)) length = width = kNaN;
      }
      if (car.size() >= 10 && car[9].is_number()) heading = car[9].get<double>();
      run_.traffic_heading_deg.push_back(heading);
      run_.traffic_length.push_back(length);
      run_.traffic_width.push_back(width);
    }
  }

  void ReadIncidents(const json* incidents, int k) {
    if (incidents == nullptr || !incidents->is_array()) return;
    for (const json& i : *incidents) {
      if (!i.is_object()) continue;
      Incident incident;
      incident.exchange = k;
      incident.t = Num(i, "t", run_.t[k]);
      incident.s = Num(i, "s");
      incident.d = Num(i, "d");
      incident.lane = Int(i, "lane", -1);
      incident.kind = Str(i, "kind", "unknown");
      incident.value = Num(i, "value");
      run_.incidents.push_back(std::move(incident));
      incident_now_ = true;
    }
  }

  Candidate ReadCandidate(const json& c) {
    Candidate out;
    out.lane = Int(c, "lane", -1);
    out.end_speed = Num(c, "end_speed");
    out.duration = Num(c, "duration");
    out.total_cost = Num(c, "total_cost");
    const json* checked = Field(c, "checked");
    out.checked = checked != nullptr && checked->is_boolean() && checked->get<bool>();
    const json* winner = Field(c, "winner");
    out.winner = winner != nullptr && winner->is_boolean() && winner->get<bool>();
    out.reject = Str(c, "reject");
    const std::vector<double> px = Numbers(Field(c, "x"));
    const std::vector<double> py = Numbers(Field(c, "y"));
    const size_t n = std::min(px.size(), py.size());
    const size_t stride = (n + kMaxCandidatePoints - 1) / kMaxCandidatePoints;
    for (size_t i = 0; i < n; ++i) {
      if (i % std::max<size_t>(stride, 1) != 0 && i + 1 != n) continue;
      if (!std::isfinite(px[i]) || !std::isfinite(py[i])) continue;
      out.x.push_back(px[i]);
      out.y.push_back(py[i]);
    }
    if (const json* costs = Field(c, "costs"); costs != nullptr && costs->is_array()) {
      for (const json& term : *costs) {
        const std::string name = Str(term, "name");
        if (name.empty()) continue;
        out.costs.push_back({TermIndex(name), Num(term, "weight"), Num(term, "value")});
      }
    }
    return out;
  }

  // The cycle's candidates (the first max_candidates listed, and the winner), offered to the
  // sampler with what may pin them: an incident at this exchange, a change of the winner's lane.
  void ReadCandidates(const json* list, int k) {
    const bool incident = std::exchange(incident_now_, false);
    const bool lane_change = k > 0 && run_.winner_lane[k] != run_.winner_lane[k - 1] &&
                             run_.winner_lane[k] >= 0 && run_.winner_lane[k - 1] >= 0;
    if (list == nullptr || !list->is_array() || list->empty()) {
      sampler_.AddWithoutCandidates(incident);
      return;
    }
    CycleCandidates cycle;
    cycle.exchange = k;
    cycle.listed = static_cast<int>(list->size());
    for (const json& c : *list) {
      if (!c.is_object()) continue;
      const json* winner = Field(c, "winner");
      const bool is_winner = winner != nullptr && winner->is_boolean() && winner->get<bool>();
      if (static_cast<int>(cycle.candidates.size()) < options_.max_candidates || is_winner) {
        cycle.candidates.push_back(ReadCandidate(c));
      }
    }
    sampler_.Add(std::move(cycle), incident, lane_change);
  }

  std::string_view source_;
  ReadOptions options_;
  const GzipStreambuf* gzip_;  // the decompressor of a gzip record, else null
  CandidateSampler sampler_;
  RunData run_;
  bool have_header_ = false;
  bool incident_now_ = false;  // an incident was read at the exchange being read
};

}  // namespace

Status ReadOptions::Validate() const {
  if (max_candidates < 1) return Status::Error("max_candidates must be >= 1");
  if (max_candidate_cycles < 1) return Status::Error("max_candidate_cycles must be >= 1");
  if (path_stride < 1) return Status::Error("path_stride must be >= 1");
  if (!(traffic_range > 0)) return Status::Error("traffic_range must be > 0 m");
  if (max_warnings < 0) return Status::Error("max_warnings must be >= 0");
  return Status::Ok();
}

StatusOr<RunData> ReadRecord(std::istream& in, std::string_view source,
                             const ReadOptions& options) {
  if (Status status = options.Validate(); !status.ok()) {
    return Status::Error(std::string(source) + ": " + status.message());
  }
  // nlohmann is used without exceptions; this only converts bad_alloc and the like at the edge.
  try {
    // 0x1f (the first byte of gzip's magic) cannot start a line of JSON text.
    if (in.peek() == 0x1f) {
      GzipStreambuf inflated(in);
      std::istream text(&inflated);
      return Reader(source, options, &inflated).Read(text);
    }
    return Reader(source, options, nullptr).Read(in);
  } catch (const std::exception& e) {
    return Status::Error(std::string(source) + ": " + e.what());
  }
}

StatusOr<RunData> ReadRecordFile(const std::string& path, const ReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open (missing or unreadable)");
  return ReadRecord(in, path, options);
}

}  // namespace frenetic::record
