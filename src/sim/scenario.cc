#include "frenetic/sim/scenario.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "frenetic/yaml/strict_reader.h"

namespace frenetic::sim {
namespace {

Status Check(bool ok, const std::string& what) {
  return ok ? Status::Ok() : Status::Error(what);
}

}  // namespace

const char* ToString(TimingOptions::Mode mode) {
  switch (mode) {
    case TimingOptions::Mode::kLockstep: return "lockstep";
    case TimingOptions::Mode::kFixed: return "fixed";
    case TimingOptions::Mode::kRandom: return "random";
  }
  return "?";
}

StatusOr<TimingOptions::Mode> ParseTimingMode(std::string_view text) {
  if (text == "lockstep") return TimingOptions::Mode::kLockstep;
  if (text == "fixed") return TimingOptions::Mode::kFixed;
  if (text == "random") return TimingOptions::Mode::kRandom;
  return Status::Error("unknown timing mode '" + std::string(text) +
                       "' (expected lockstep, fixed or random)");
}

Status TimingOptions::Validate() const {
  if (l_old < 0 || l_old > 50) return Status::Error("timing.l_old must be in [0, 50]");
  if (l_new < 1 || l_new > 50) return Status::Error("timing.l_new must be in [1, 50]");
  if (l_old_min < 0 || l_old_max < l_old_min || l_old_max > 50)
    return Status::Error("timing.l_old_range must satisfy 0 <= min <= max <= 50");
  if (l_new_min < 1 || l_new_max < l_new_min || l_new_max > 50)
    return Status::Error("timing.l_new_range must satisfy 1 <= min <= max <= 50");
  return Status::Ok();
}

Status TrafficOptions::Validate() const {
  Status s;
  auto check = [&](bool ok, const char* what) {
    if (s.ok() && !ok) s = Status::Error(std::string("traffic.") + what);
  };
  check(cars >= 0 && cars <= 200, "cars must be in [0, 200]");
  check(respawn_distance > 0, "respawn_distance must be > 0");
  check(batch_min >= 1 && batch_max >= batch_min, "batch must satisfy 1 <= min <= max");
  check(period_min_frames >= 1 && period_max_frames >= period_min_frames,
        "period_frames must satisfy 1 <= min <= max");
  check(frame_rate >= 1 && frame_rate <= 1000, "frame_rate must be in [1, 1000] Hz");
  check(spawn_retries >= 1, "spawn_retries must be >= 1");
  check(spawn_clearance >= 0, "spawn_clearance must be >= 0");
  check(behind_offset_min <= behind_offset_max, "behind_offsets must satisfy min <= max");
  check(ahead_offset_min <= ahead_offset_max, "ahead_offsets must satisfy min <= max");
  check(behind_speed_min_mph > 0 && behind_speed_max_mph >= behind_speed_min_mph,
        "behind_speed_mph must satisfy 0 < min <= max");
  check(ahead_speed_min_mph > 0 && ahead_speed_max_mph >= ahead_speed_min_mph,
        "ahead_speed_mph must satisfy 0 < min <= max");
  check(max_accel > 0, "max_accel must be > 0");
  check(throttle_gain > 0, "throttle_gain must be > 0");
  check(drag >= 0, "drag must be >= 0");
  check(linear_drag >= 0, "linear_drag must be >= 0");
  check(brake_decel > 0, "brake_decel must be > 0");
  check(brake_gap_min >= 0 && brake_gap_max >= brake_gap_min,
        "brake_gap must satisfy 0 <= min <= max");
  check(brake_delay >= 0 && brake_delay <= 2, "brake_delay must be in [0, 2] s");
  check(brake_release_delay <= 2, "brake_release_delay must be <= 2 s (negative: brake_delay)");
  check(follow_lateral > 0, "follow_lateral must be > 0");
  check(wander_min >= 0 && wander_max >= wander_min && wander_max <= 2,
        "wander must satisfy 0 <= min <= max <= 2");
  check(wander_period_min > 0 && wander_period_max >= wander_period_min,
        "wander_period must satisfy 0 < min <= max");
  check(throttle_wander >= 0 && throttle_wander < 1, "throttle_wander must be in [0, 1)");
  check(wander_full_speed >= 0, "wander_full_speed must be >= 0");
  check(lane_change_gap >= 0, "lane_change_gap must be >= 0");
  check(lane_change_ego_band >= 0, "lane_change_ego_band must be >= 0");
  check(lane_change_spacing_ticks >= 0, "lane_change_spacing_ticks must be >= 0");
  check(lane_change_evaluations >= 0, "lane_change_evaluations must be >= 0");
  check(lane_change_duration > 0, "lane_change_duration must be > 0");
  check(waypoint_window > 0, "waypoint_window must be > 0");
  check(seam_glitch_window >= 0, "seam_glitch_window must be >= 0");
  check(cut_in_rate >= 0, "cut_in.rate must be >= 0");
  check(cut_in_min_gap >= 0 && cut_in_max_gap >= cut_in_min_gap,
        "cut_in.gap must satisfy 0 <= min <= max");
  check(cut_in_duration > 0, "cut_in.duration must be > 0");
  check(cut_in_max_closing >= 0, "cut_in.max_closing must be >= 0");
  check(hard_brake_rate >= 0, "hard_brake.rate must be >= 0");
  check(hard_brake_decel > 0, "hard_brake.decel must be > 0");
  check(hard_brake_duration > 0, "hard_brake.duration must be > 0");
  check(hard_brake_max_distance > 0, "hard_brake.max_distance must be > 0");
  check(event_cooldown >= 0, "event_cooldown must be >= 0");
  check(blockade_distance > 0, "blockade.distance must be > 0");
  check(blockade_speed >= 0, "blockade.speed must be >= 0");
  check(blockade_seconds >= 0, "blockade.seconds must be >= 0");
  check(!blockade || cars >= 3, "blockade needs at least 3 cars");
  return s;
}

Status IncidentOptions::Validate() const {
  if (!(speed_limit_mph > 0)) return Status::Error("incidents.speed_limit_mph must be > 0");
  if (!(acc_limit > 0)) return Status::Error("incidents.acc_limit must be > 0");
  if (!(jerk_limit > 0)) return Status::Error("incidents.jerk_limit must be > 0");
  if (lane_line_ticks < 0) return Status::Error("incidents.lane_line_ticks must be >= 0");
  if (display_hold_frames < 0) return Status::Error("incidents.display_hold_frames must be >= 0");
  if (merge_ticks < 0) return Status::Error("incidents.merge_ticks must be >= 0");
  return Status::Ok();
}

Status Scenario::Validate() const {
  const std::string where = source.empty() ? name : source;
  auto wrap = [&](Status s) {
    return s.ok() ? s : Status::Error(where + ": " + s.message());
  };
  if (Status s = Check(car_length > 0 && car_width > 0 && car_length < 50 && car_width < 20,
                       "car length and width must be in (0, 50) and (0, 20) m");
      !s.ok())
    return wrap(s);
  if (Status s = timing.Validate(); !s.ok()) return wrap(s);
  if (Status s = traffic.Validate(); !s.ok()) return wrap(s);
  if (Status s = incidents.Validate(); !s.ok()) return wrap(s);
  return Status::Ok();
}

namespace {

// Files being loaded, outermost first (canonical paths), to report a `base` cycle.
using BaseChain = std::vector<std::string>;

bool IsScenarioName(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
  });
}

std::string CanonicalPath(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : p.string();
}

StatusOr<Scenario> Parse(std::string_view yaml_text, const std::string& source, BaseChain* chain);

// Reads and parses a scenario file; `chain` holds the files that named it as their base.
StatusOr<Scenario> LoadFile(const std::string& path, BaseChain* chain) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open scenario file");
  std::stringstream ss;
  ss << in.rdbuf();
  return Parse(ss.str(), path, chain);
}

// The scenario named by `base` in the file `source`: a bundled name or a path relative to the
// file's directory. A file already in `chain` is a cycle.
StatusOr<Scenario> LoadBase(const std::string& base, const std::string& source, BaseChain* chain) {
  std::string path = base;
  if (IsScenarioName(base)) {
    path = ScenarioDir() + "/" + base + ".yaml";
  } else if (std::filesystem::path(base).is_relative()) {
    path = (std::filesystem::path(source).parent_path() / base).string();
  }
  const std::string canonical = CanonicalPath(path);
  if (std::find(chain->begin(), chain->end(), canonical) != chain->end()) {
    std::string cycle;
    for (const auto& f : *chain) cycle += f + " -> ";
    return Status::Error(source + ": 'base' cycle: " + cycle + canonical);
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return Status::Error(source + ": 'base' scenario '" + base + "' not found (" + path + ")");
  }
  return LoadFile(path, chain);
}

StatusOr<Scenario> Parse(std::string_view yaml_text, const std::string& source, BaseChain* chain) {
  auto root = yaml::Load(yaml_text, source);
  if (!root.ok()) return root.status();
  Scenario sc;
  yaml::MapReader r(*root, source);
  // `base: NAME or FILE` loads that scenario first; this file's keys then override its values
  // (key by key, maps merged); name, description and source are this file's.
  if (r.Has("base")) {
    std::string base;
    r.Read("base", &base);
    if (!r.ok()) return r.status();
    chain->push_back(CanonicalPath(source));
    auto loaded = LoadBase(base, source, chain);
    chain->pop_back();
    if (!loaded.ok()) return loaded.status();
    sc = std::move(*loaded);
    sc.description.clear();
  } else {
    r.MarkKnown("base");
  }
  sc.source = source;
  r.Read("name", &sc.name);
  r.Read("description", &sc.description);
  r.Read("seed", &sc.seed);

  {
    yaml::MapReader car = r.Sub("car");
    car.Read("length", &sc.car_length);
    car.Read("width", &sc.car_width);
    car.Finish();
  }
  if (r.Has("start")) {
    if (r.Child("start").IsScalar()) {
      std::string v;
      r.Read("start", &v);
      if (v != "auto") r.Fail("start", "must be 'auto' or a map with x, y or s, lane/d");
      sc.start = StartPose();
    } else {
      yaml::MapReader start = r.Sub("start");
      StartPose& p = sc.start;
      bool has_xy = start.Has("x") || start.Has("y");
      bool has_s = start.Has("s");
      if (has_xy && has_s) start.Fail("start", "has both x/y and s");
      if (has_xy) {
        if (!start.Has("x") || !start.Has("y")) start.Fail("start", "needs both x and y");
        p.kind = StartPose::Kind::kXY;
      } else if (has_s) {
        p.kind = StartPose::Kind::kFrenet;
      }
      start.Read("x", &p.x);
      start.Read("y", &p.y);
      start.Read("yaw", &p.yaw_deg);
      start.Read("s", &p.s);
      start.Read("d", &p.d);
      if (start.Has("lane")) {
        int lane = 1;
        start.Read("lane", &lane);
        if (start.ok() && (lane < 0 || lane > 2)) start.Fail("start.lane", "must be 0, 1 or 2");
        if (start.Has("d")) start.Fail("start", "has both lane and d");
        p.d = 2 + 4 * lane;
      } else {
        int unused = 0;
        start.Read("lane", &unused);
      }
      start.Finish();
    }
  } else {
    r.Sub("start");
  }
  {
    yaml::MapReader t = r.Sub("timing");
    std::string mode = ToString(sc.timing.mode);
    t.Read("mode", &mode);
    if (t.ok()) {
      auto m = ParseTimingMode(mode);
      if (!m.ok()) t.Fail("timing.mode", "'" + mode + "' is not lockstep, fixed or random");
      else sc.timing.mode = *m;
    }
    t.Read("l_old", &sc.timing.l_old);
    t.Read("l_new", &sc.timing.l_new);
    t.ReadPair("l_old_range", &sc.timing.l_old_min, &sc.timing.l_old_max);
    t.ReadPair("l_new_range", &sc.timing.l_new_min, &sc.timing.l_new_max);
    t.Finish();
  }
  {
    TrafficOptions& o = sc.traffic;
    yaml::MapReader t = r.Sub("traffic");
    t.Read("cars", &o.cars);
    t.Read("respawn_distance", &o.respawn_distance);
    t.ReadPair("batch", &o.batch_min, &o.batch_max);
    t.ReadPair("period_frames", &o.period_min_frames, &o.period_max_frames);
    t.Read("frame_rate", &o.frame_rate);
    t.Read("spawn_retries", &o.spawn_retries);
    t.Read("spawn_clearance", &o.spawn_clearance);
    t.ReadPair("behind_offsets", &o.behind_offset_min, &o.behind_offset_max);
    t.ReadPair("ahead_offsets", &o.ahead_offset_min, &o.ahead_offset_max);
    t.ReadPair("behind_speed_mph", &o.behind_speed_min_mph, &o.behind_speed_max_mph);
    t.ReadPair("ahead_speed_mph", &o.ahead_speed_min_mph, &o.ahead_speed_max_mph);
    t.Read("max_accel", &o.max_accel);
    t.Read("throttle_gain", &o.throttle_gain);
    t.Read("drag", &o.drag);
    t.Read("linear_drag", &o.linear_drag);
    t.Read("brake_decel", &o.brake_decel);
    t.ReadPair("brake_gap", &o.brake_gap_min, &o.brake_gap_max);
    t.Read("brake_delay", &o.brake_delay);
    t.Read("brake_release_delay", &o.brake_release_delay);
    t.Read("brake_to_leader_mph", &o.brake_to_leader_mph);
    t.Read("follow_lateral", &o.follow_lateral);
    t.ReadPair("wander", &o.wander_min, &o.wander_max);
    t.ReadPair("wander_period", &o.wander_period_min, &o.wander_period_max);
    t.Read("wander_full_speed", &o.wander_full_speed);
    t.Read("throttle_wander", &o.throttle_wander);
    t.Read("lane_changes", &o.lane_changes);
    t.Read("lane_change_gap", &o.lane_change_gap);
    t.Read("lane_change_ego_band", &o.lane_change_ego_band);
    t.Read("lane_change_min_mph", &o.lane_change_min_mph);
    t.Read("lane_change_spacing_ticks", &o.lane_change_spacing_ticks);
    t.Read("lane_change_evaluations", &o.lane_change_evaluations);
    t.Read("lane_change_duration", &o.lane_change_duration);
    t.Read("waypoint_window", &o.waypoint_window);
    t.Read("spawn_speed_quirk", &o.spawn_speed_quirk);
    t.Read("seam_glitch", &o.seam_glitch);
    t.Read("seam_glitch_window", &o.seam_glitch_window);
    t.Read("event_cooldown", &o.event_cooldown);
    {
      yaml::MapReader c = t.Sub("cut_in");
      c.Read("rate", &o.cut_in_rate);
      c.ReadPair("gap", &o.cut_in_min_gap, &o.cut_in_max_gap);
      c.Read("duration", &o.cut_in_duration);
      c.Read("max_closing", &o.cut_in_max_closing);
      c.Finish();
    }
    {
      yaml::MapReader h = t.Sub("hard_brake");
      h.Read("rate", &o.hard_brake_rate);
      h.Read("decel", &o.hard_brake_decel);
      h.Read("duration", &o.hard_brake_duration);
      h.Read("max_distance", &o.hard_brake_max_distance);
      h.Finish();
    }
    {
      yaml::MapReader b = t.Sub("blockade");
      b.Read("enabled", &o.blockade);
      b.Read("distance", &o.blockade_distance);
      b.Read("speed", &o.blockade_speed);
      b.Read("seconds", &o.blockade_seconds);
      b.Finish();
    }
    t.Finish();
  }
  {
    IncidentOptions& o = sc.incidents;
    yaml::MapReader i = r.Sub("incidents");
    i.Read("speed_limit_mph", &o.speed_limit_mph);
    i.Read("acc_limit", &o.acc_limit);
    i.Read("jerk_limit", &o.jerk_limit);
    i.Read("lane_line_ticks", &o.lane_line_ticks);
    i.Read("display_hold_frames", &o.display_hold_frames);
    i.Read("merge_ticks", &o.merge_ticks);
    i.Finish();
  }
  r.Finish();
  if (!r.ok()) return r.status();
  if (!r.Has("name")) sc.name = std::filesystem::path(source).stem().string();
  if (Status s = sc.Validate(); !s.ok()) return s;
  return sc;
}

}  // namespace

StatusOr<Scenario> ParseScenario(std::string_view yaml_text, std::string_view source_view) {
  BaseChain chain;
  return Parse(yaml_text, std::string(source_view), &chain);
}

std::string ScenarioDir() { return std::string(FRENETIC_SOURCE_DIR) + "/config/scenarios"; }

std::vector<std::string> ScenarioNames() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(ScenarioDir(), ec)) {
    if (e.path().extension() == ".yaml") names.push_back(e.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

StatusOr<Scenario> LoadScenario(const std::string& name_or_path) {
  const bool is_name = IsScenarioName(name_or_path);
  const std::string path = is_name ? ScenarioDir() + "/" + name_or_path + ".yaml" : name_or_path;
  std::error_code ec;
  if (is_name && !std::filesystem::is_regular_file(path, ec)) {
    std::string known;
    for (const auto& n : ScenarioNames()) known += (known.empty() ? "" : ", ") + n;
    return Status::Error("unknown scenario '" + name_or_path + "' (known: " + known + ")");
  }
  BaseChain chain;
  auto sc = LoadFile(path, &chain);
  if (sc.ok() && is_name && sc->name.empty()) sc->name = name_or_path;
  return sc;
}

}  // namespace frenetic::sim
