// The writer's thread formats each line from a copy of the exchange's values (the planning
// thread only copies), compresses it and writes it; a bounded queue between them keeps a slow
// disk from holding the whole record in memory (the planning thread then waits between cycles,
// never inside one).
#include "frenetic/sim/record.h"

#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>
#include <zlib.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "frenetic/wire/protocol.h"

namespace frenetic::sim {
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

nlohmann::json Finite(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json Costs(const std::vector<plan::CostTermValue>& terms) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& t : terms) {
    a.push_back({{"name", t.name}, {"weight", Finite(t.weight)}, {"value", Finite(t.value)}});
  }
  return a;
}

// The strategic layer's decision: the plans it weighed and the one chosen.
nlohmann::json Strategy(const plan::StrategySummary& st) {
  nlohmann::json plans = nlohmann::json::array();
  for (int i = 0; i < st.num_plans && i < plan::StrategySummary::kMaxPlans; ++i) {
    const plan::StrategyPlan& p = st.plans[i];
    nlohmann::json lanes = nlohmann::json::array();
    for (const int l : p.lanes) {
      if (l >= 0) lanes.push_back(l);
    }
    plans.push_back({{"lanes", lanes},
                     {"mode", plan::ToString(p.mode)},
                     {"car", p.car >= 0 ? nlohmann::json(p.car) : nlohmann::json(nullptr)},
                     {"t_change", p.t_change >= 0 ? Finite(p.t_change) : nlohmann::json(nullptr)},
                     {"progress", Finite(p.progress)},
                     {"value", Finite(p.value)}});
  }
  return {{"chosen", st.chosen}, {"plans", plans}};
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

// Lines queued for the writer's thread at most (~5-30 kB each); a producer that finds the queue
// full waits until it is half empty, so that the planning thread then runs many cycles in a row
// instead of trading the core (and its caches) with the writer at every exchange.
constexpr std::size_t kMaxQueuedLines = 512;
// The writer's thread wakes up for this many queued lines (or a flush, the footer, the end):
// lines are written in bursts, not one wake-up per exchange.
constexpr std::size_t kBatchLines = 64;
// The gzip stream is flushed to a byte boundary this often (raw bytes), so a drive that dies
// still leaves a record that reads up to about there.
constexpr std::size_t kSyncFlushBytes = 4 << 20;
constexpr int kGzipLevel = 6;

// What an exchange line needs from the simulator, copied when the exchange is written.
struct Metrics {
  double speed_mph, acc, acc_t, acc_n, jerk, gap, headway, distance_m, curr_miles, best_miles;
  int lane, leader, l_old, l_new;
};

Metrics MetricsOf(const Simulator& sim, int l_old, int l_new) {
  const IncidentMonitor& m = sim.monitor();
  const LeaderGap lead = sim.leader();
  return {sim.ego().speed() * kMpsToMph,
          m.last_acc(),
          m.last_acc_t(),
          m.last_acc_n(),
          m.last_jerk(),
          lead.gap,
          lead.headway,
          m.distance(),
          m.current_miles(),
          m.best_miles(),
          sim.lane(),
          lead.id,
          l_old,
          l_new};
}

std::vector<Incident> IncidentsSince(const Simulator& sim, std::size_t first) {
  const std::vector<Incident>& log = sim.monitor().log();
  return {log.begin() + static_cast<std::ptrdiff_t>(std::min(first, log.size())), log.end()};
}

// The exchange line: the fields every exchange has around the given path and plan objects.
void FormatExchange(int index, double t, const std::string& telemetry_json,
                    const std::vector<double>& path_x, const std::vector<double>& path_y,
                    const nlohmann::json& plan, const Metrics& mt,
                    const std::vector<Incident>& new_incidents, std::string* line) {
  const bool has_leader = mt.leader >= 0;
  nlohmann::json metrics = {{"speed_mph", mt.speed_mph},
                            {"acc", mt.acc},
                            {"acc_t", mt.acc_t},
                            {"acc_n", mt.acc_n},
                            {"jerk", mt.jerk},
                            {"lane", mt.lane},
                            {"gap", has_leader ? Finite(mt.gap) : nlohmann::json()},
                            {"headway", has_leader ? Finite(mt.headway) : nlohmann::json()},
                            {"leader", mt.leader},
                            {"distance_m", mt.distance_m},
                            {"curr_miles", mt.curr_miles},
                            {"best_miles", mt.best_miles},
                            {"l_old", mt.l_old},
                            {"l_new", mt.l_new}};
  nlohmann::json incidents = nlohmann::json::array();
  for (const Incident& inc : new_incidents) {
    incidents.push_back({{"t", inc.t},
                         {"s", inc.s},
                         {"d", inc.d},
                         {"lane", inc.lane},
                         {"kind", ToString(inc.kind)},
                         {"value", inc.value}});
  }
  // 0.1 mm is far below the float32 resolution the simulator parses to; it halves the file.
  auto rounded = [](const std::vector<double>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (double e : v) a.push_back(std::isfinite(e) ? std::round(e * 1e4) / 1e4 : 0.0);
    return a;
  };
  nlohmann::json rest = {{"path", {{"x", rounded(path_x)}, {"y", rounded(path_y)}}},
                         {"plan", plan},
                         {"metrics", metrics},
                         {"incidents", incidents}};
  // The telemetry is spliced in as the simulator's own text (wire::TelemetryToJson).
  *line += "{\"type\":\"exchange\",\"i\":";
  *line += std::to_string(index);
  *line += ",\"t\":";
  *line += nlohmann::json(t).dump();
  *line += ",\"telemetry\":";
  *line += telemetry_json.empty() ? "null" : telemetry_json;
  *line += ",";
  *line += rest.dump().substr(1);
}

}  // namespace

// The record's file: plain, or one gzip stream (zlib, deterministic: no name, time 0).
class RecordWriter::Sink {
 public:
  static StatusOr<std::unique_ptr<Sink>> Open(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) {
      return Status::Error(path + ": cannot write record: " + std::strerror(errno));
    }
    auto sink = std::unique_ptr<Sink>(new Sink(f, path));
    const bool gzip = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
    if (gzip) {
      sink->zs_ = std::make_unique<z_stream>();
      *sink->zs_ = z_stream{};
      // 15 window bits + 16: a gzip header and trailer around the deflate stream.
      if (deflateInit2(sink->zs_.get(), kGzipLevel, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) !=
          Z_OK) {
        sink->zs_.reset();
        return Status::Error(path + ": cannot start the gzip stream");
      }
      sink->out_.resize(256 << 10);
    }
    return sink;
  }
  ~Sink() {
    Finish();
    if (zs_) deflateEnd(zs_.get());
    std::fclose(file_);
  }

  void Write(std::string_view data) {
    if (!error_.empty() || finished_) return;
    if (!zs_) {
      if (std::fwrite(data.data(), 1, data.size(), file_) != data.size()) Fail(errno);
      return;
    }
    Deflate(data, Z_NO_FLUSH);
    since_flush_ += data.size();
    if (since_flush_ >= kSyncFlushBytes) Deflate({}, Z_SYNC_FLUSH);
  }
  // Everything written so far is in the file (readable, for gzip up to a flush point).
  void Flush() {
    if (!error_.empty()) return;
    if (zs_ && !finished_) Deflate({}, Z_SYNC_FLUSH);
    if (std::fflush(file_) != 0) Fail(errno);
  }
  // Ends the stream (the gzip trailer) and flushes; later writes are dropped.
  void Finish() {
    if (finished_) return;
    if (zs_ && error_.empty()) Deflate({}, Z_FINISH);
    finished_ = true;
    if (error_.empty() && std::fflush(file_) != 0) Fail(errno);
  }
  const std::string& error() const { return error_; }
  const std::string& path() const { return path_; }

 private:
  Sink(std::FILE* file, std::string path) : file_(file), path_(std::move(path)) {
    std::setvbuf(file_, nullptr, _IOFBF, 1 << 20);
  }

  void Deflate(std::string_view data, int flush) {
    zs_->next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
    zs_->avail_in = static_cast<uInt>(data.size());
    int rc = Z_OK;
    do {
      zs_->next_out = reinterpret_cast<Bytef*>(out_.data());
      zs_->avail_out = static_cast<uInt>(out_.size());
      rc = deflate(zs_.get(), flush);
      if (rc == Z_STREAM_ERROR) {
        error_ = "gzip stream error";
        return;
      }
      const std::size_t n = out_.size() - zs_->avail_out;
      if (n > 0 && std::fwrite(out_.data(), 1, n, file_) != n) {
        Fail(errno);
        return;
      }
    } while (zs_->avail_out == 0 || (flush == Z_FINISH && rc != Z_STREAM_END));
    if (flush != Z_NO_FLUSH) since_flush_ = 0;
  }
  void Fail(int err) {
    if (error_.empty()) error_ = std::string("write failed: ") + std::strerror(err);
  }

  std::FILE* file_;
  std::string path_;
  std::unique_ptr<z_stream> zs_;  // null: plain text
  std::string out_;
  std::size_t since_flush_ = 0;
  bool finished_ = false;
  std::string error_;
};

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
                      {"end_speed", Finite(c.end_speed)},
                      {"duration", Finite(c.duration)},
                      {"total_cost", Finite(c.total_cost)},
                      {"checked", c.checked},
                      {"winner", c.winner},
                      {"reject", reject},
                      {"reject_car", c.reject_car >= 0 ? nlohmann::json(c.reject_car)
                                                       : nlohmann::json(nullptr)},
                      {"reject_t", Finite(c.reject_time)},
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
          {"winner_total_cost", Finite(s.winner_total_cost)},
          {"winner_lane", s.winner_lane},
          {"winner_end_speed", Finite(s.winner_end_speed)},
          {"winner_duration", Finite(s.winner_duration)},
          {"refine_iterations", s.refine_iterations},
          {"deadline_stage", plan::ToString(s.deadline_stage)},
          {"refine_cost_before", Finite(s.refine_cost_before)},
          {"refine_cost_after", Finite(s.refine_cost_after)},
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

StatusOr<std::unique_ptr<RecordWriter>> RecordWriter::Open(const std::string& path) {
  auto sink = Sink::Open(path);
  if (!sink.ok()) return sink.status();
  return std::unique_ptr<RecordWriter>(new RecordWriter(std::move(sink).value()));
}

RecordWriter::RecordWriter(std::unique_ptr<Sink> sink) : sink_(std::move(sink)) {
  thread_ = std::thread([this] { Loop(); });
}

RecordWriter::~RecordWriter() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  work_.notify_all();
  thread_.join();
  sink_->Finish();
}

void RecordWriter::Loop() {
  // The record is no reason to take a core from the planner: the writer runs as a batch job at
  // low priority (also when the drive runs under a real-time policy, which a thread may always
  // leave), so it yields to the planning thread. Policy and nice are per thread on Linux;
  // failing to lower them is harmless.
  const sched_param batch{};
  (void)pthread_setschedparam(pthread_self(), SCHED_BATCH, &batch);
  (void)setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 10);
  std::string line;
  std::unique_lock lock(mutex_);
  for (;;) {
    work_.wait(lock,
               [this] { return stop_ || last_ || drain_ > 0 || queue_.size() >= kBatchLines; });
    if (queue_.empty()) {
      if (stop_) return;  // everything written
      room_.notify_all();
      if (last_ || drain_ > 0) {
        // Nothing to do until more lines come: wait for them, not for the predicate above.
        work_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      }
      continue;
    }
    Line next = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    const bool last = last_ && queue_.empty();
    if (queue_.size() <= kMaxQueuedLines / 2) room_.notify_all();
    lock.unlock();
    line.clear();
    next(&line);
    line.push_back('\n');
    sink_->Write(line);
    if (last) sink_->Finish();
    lock.lock();
    busy_ = false;
    if (queue_.empty()) room_.notify_all();
  }
}

void RecordWriter::Queue(Line line, bool last) {
  if (finished_) return;  // nothing follows the footer
  finished_ = last;
  std::unique_lock lock(mutex_);
  if (queue_.size() >= kMaxQueuedLines) {
    room_.wait(lock, [this] { return queue_.size() <= kMaxQueuedLines / 2; });
  }
  queue_.push_back(std::move(line));
  last_ = last;
  if (last || queue_.size() >= kBatchLines) work_.notify_one();
}

Status RecordWriter::status() {
  std::unique_lock lock(mutex_);
  ++drain_;
  work_.notify_one();
  room_.wait(lock, [this] { return queue_.empty() && !busy_; });
  --drain_;
  // Only this thread queues lines: the writer's thread stays idle while the file is flushed.
  sink_->Flush();
  if (!sink_->error().empty()) return Status::Error(sink_->path() + ": " + sink_->error());
  return Status::Ok();
}

void RecordWriter::TraceByReplay(std::unique_ptr<plan::Planner> replica, int max_candidates) {
  std::lock_guard lock(mutex_);  // the writer's thread reads replica_ under the same lock
  replica_ = std::move(replica);
  if (replica_) {
    replica_->Reset();
    replica_->set_trace(&replica_trace_, max_candidates);
  }
}

bool RecordWriter::Replay(int index, const std::string& telemetry_json,
                          const std::vector<double>& path_x, const std::vector<double>& path_y,
                          plan::PlanSummary* summary,
                          std::vector<plan::CandidateTrace>* candidates) {
  // The telemetry as the planner received it: what ParseFrame makes of the text sent
  // (wire::TelemetryAsReceived), whatever its size.
  wire::FrameLimits unlimited;
  unlimited.max_sensor_rows = 100000;
  unlimited.max_path_points = 1000000;
  const wire::ParsedFrame frame =
      wire::ParseFrame("42[\"telemetry\"," + telemetry_json + "]", unlimited);
  const plan::PlanResult* r = nullptr;
  if (frame.kind == wire::FrameKind::kTelemetry) {
    replica_trace_.candidates.clear();
    r = &replica_->Plan(frame.telemetry);
  }
  if (r == nullptr || r->x != path_x || r->y != path_y) {
    spdlog::warn(
        "record: the replica that traces the candidates planned exchange {} otherwise "
        "than the planner that drove{}; candidates are left out from there on",
        index, r == nullptr ? " (its telemetry did not parse)" : "");
    std::lock_guard lock(mutex_);
    replica_.reset();
    return false;
  }
  // The counts of the traced search; the timings stay the driving planner's.
  plan::PlanSummary traced = r->summary;
  traced.ms_prepare = summary->ms_prepare;
  traced.ms_generate = summary->ms_generate;
  traced.ms_score = summary->ms_score;
  traced.ms_check = summary->ms_check;
  traced.ms_refine = summary->ms_refine;
  traced.ms_output = summary->ms_output;
  traced.ms_total = summary->ms_total;
  traced.deadline_stage = summary->deadline_stage;
  *summary = std::move(traced);
  candidates->swap(replica_trace_.candidates);
  return true;
}

void RecordWriter::WriteHeader(const Simulator& sim, const std::string& planner_name,
                               const nlohmann::json& config, std::string_view connect_url) {
  const World& w = sim.world();
  nlohmann::json centre = nlohmann::json::array();
  const double length = w.line->length();
  const int n = std::max(4, static_cast<int>(std::ceil(length / 2.0)));
  auto round3 = [](double v) { return std::round(v * 1000.0) / 1000.0; };
  for (int i = 0; i < n; ++i) {
    const map::CartesianPose p = w.line->ToCartesian(length * i / n, 0.0);
    centre.push_back({round3(p.x), round3(p.y)});
  }
  const Scenario& sc = sim.scenario();
  nlohmann::json h = {{"type", "header"},
                      {"version", 1},
                      {"map", w.map_path},
                      {"max_s", w.track.max_s},
                      {"lane_width", 4},
                      {"lanes", 3},
                      {"scenario", sc.name},
                      {"seed", sim.seed()},
                      {"planner", planner_name},
                      {"config", config},
                      {"timing", ToString(sc.timing.mode)},
                      {"cars", sc.traffic.cars},
                      {"centerline", centre},
                      {"car_length", sc.car_length},
                      {"car_width", sc.car_width}};
  if (!connect_url.empty()) h["connect"] = connect_url;
  Queue([text = h.dump()](std::string* line) { *line += text; });
}

void RecordWriter::WriteExchange(int index, double t, const std::string& telemetry_json,
                                 const plan::PlanResult& result, const plan::CycleTrace* trace,
                                 double plan_ms, const Simulator& sim,
                                 std::size_t first_incident, int l_old, int l_new) {
  const double k = timing_ ? 1.0 : 0.0;  // timing off: every time field is 0 (byte-stable)
  Queue([this, index, t, telemetry_json, status = result.status, k, plan_ms,
         summary = result.summary,
         candidates = trace != nullptr ? trace->candidates : std::vector<plan::CandidateTrace>(),
         path_x = result.x, path_y = result.y, metrics = MetricsOf(sim, l_old, l_new),
         incidents = IncidentsSince(sim, first_incident)](std::string* line) mutable {
    bool replay = false;
    {
      std::lock_guard lock(mutex_);
      replay = replica_ != nullptr;
    }
    if (replay) {
      candidates.clear();
      Replay(index, telemetry_json, path_x, path_y, &summary, &candidates);
    }
    nlohmann::json plan = PlanJson(status, summary, plan_ms, k, candidates);
    if (summary.strategy.num_plans > 0) plan["strategy"] = Strategy(summary.strategy);
    FormatExchange(index, t, telemetry_json, path_x, path_y, plan, metrics, incidents, line);
  });
}

void RecordWriter::WriteRemoteExchange(int index, double t, const std::string& telemetry_json,
                                       std::span<const double> path_x,
                                       std::span<const double> path_y, std::string_view reply,
                                       double round_trip_ms, const Simulator& sim,
                                       std::size_t first_incident, int l_old, int l_new) {
  const double k = timing_ ? 1.0 : 0.0;
  Queue([index, t, telemetry_json, reply = std::string(reply), ms = k * round_trip_ms,
         path_x = std::vector<double>(path_x.begin(), path_x.end()),
         path_y = std::vector<double>(path_y.begin(), path_y.end()),
         metrics = MetricsOf(sim, l_old, l_new),
         incidents = IncidentsSince(sim, first_incident)](std::string* line) {
    const nlohmann::json plan = {{"status", reply}, {"ms_total", ms}};
    FormatExchange(index, t, telemetry_json, path_x, path_y, plan, metrics, incidents, line);
  });
}

void RecordWriter::WriteLine(std::function<void(std::string* line)> format, bool last) {
  Queue(std::move(format), last);
}

void RecordWriter::WriteFooter(const DriveReport& report) {
  nlohmann::json f = {{"type", "footer"}, {"report", report.ToJson()}};
  if (!timing_) f["report"]["plan_ms"] = {{"p50", 0}, {"p99", 0}, {"max", 0}};
  Queue([text = f.dump()](std::string* line) { *line += text; }, /*last=*/true);
}

}  // namespace frenetic::sim
