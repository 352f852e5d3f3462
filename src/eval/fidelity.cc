// Recordings, the protocol, Frenet and ego-motion checks of `frenetic fidelity`. The traffic
// statistics are in fidelity_traffic.cc.
#include "frenetic/eval/fidelity.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "frenetic/sim/ego.h"
#include "frenetic/units.h"
#include "frenetic/wire/protocol.h"

namespace frenetic::sim {
namespace {

using nlohmann::json;

constexpr std::size_t kMaxFailures = 5;
// Slack on "digits" tolerances for the decimal -> double parse of the recorded text.
constexpr double kDigitSlack = 1e-6;

// Splits text into its non-blank lines, keeping the 1-based line number.
std::vector<std::pair<int, std::string_view>> Lines(std::string_view text) {
  std::vector<std::pair<int, std::string_view>> out;
  int number = 0;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
    ++number;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
    if (!line.empty()) out.emplace_back(number, line);
  }
  return out;
}

// Reads number field `key` of `j`; names the field on failure.
bool ReadNumber(const json& j, const char* key, double* out, std::string* error) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number()) {
    *error = std::string("field '") + key + "' is missing or not a number";
    return false;
  }
  *out = it->get<double>();
  return true;
}

bool ReadNumbers(const json& j, const char* key, std::vector<double>* out, std::string* error) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_array()) {
    *error = std::string("field '") + key + "' is missing or not an array";
    return false;
  }
  out->clear();
  for (const json& v : *it) {
    if (!v.is_number()) {
      *error = std::string("field '") + key + "' holds a non-number";
      return false;
    }
    out->push_back(v.get<double>());
  }
  return true;
}

bool ParseMessage(std::string_view line, RecordedMessage* m, std::string* error) {
  const json j = json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) {
    *error = "not a JSON object";
    return false;
  }
  m->json = std::string(line);
  if (!ReadNumber(j, "x", &m->x, error) || !ReadNumber(j, "y", &m->y, error) ||
      !ReadNumber(j, "yaw", &m->yaw_deg, error) || !ReadNumber(j, "speed", &m->speed_mph, error) ||
      !ReadNumber(j, "s", &m->s, error) || !ReadNumber(j, "d", &m->d, error) ||
      !ReadNumber(j, "end_path_s", &m->end_path_s, error) ||
      !ReadNumber(j, "end_path_d", &m->end_path_d, error) ||
      !ReadNumbers(j, "previous_path_x", &m->path_x, error) ||
      !ReadNumbers(j, "previous_path_y", &m->path_y, error)) {
    return false;
  }
  if (m->path_x.size() != m->path_y.size()) {
    *error = "previous_path_x and previous_path_y differ in length";
    return false;
  }
  const auto sf = j.find("sensor_fusion");
  if (sf == j.end() || !sf->is_array()) {
    *error = "field 'sensor_fusion' is missing or not an array";
    return false;
  }
  for (const json& row : *sf) {
    if (!row.is_array() || row.size() != 7) {
      *error = "a sensor_fusion row is not an array of 7 numbers";
      return false;
    }
    std::array<double, 7> r{};
    for (int i = 0; i < 7; ++i) {
      if (!row[i].is_number()) {
        *error = "a sensor_fusion row holds a non-number";
        return false;
      }
      r[i] = row[i].get<double>();
    }
    m->sensor_fusion.push_back(r);
  }
  return true;
}

void Fail(CheckRow* row, std::string text) {
  if (row->failures.size() < kMaxFailures) row->failures.push_back(std::move(text));
}

std::string Fmt(const char* format, auto... args) {
  char buf[256];
  std::snprintf(buf, sizeof buf, format, args...);
  return buf;
}

// The unit of the 7th significant digit of a float printed by .NET's float.ToString().
double SeventhDigit(double v) {
  const double a = std::abs(v);
  if (a == 0 || !std::isfinite(a)) return 0;
  return std::pow(10.0, std::floor(std::log10(a)) - 6);
}

class SimulatorEgo final : public EgoModel {
 public:
  SimulatorEgo(float x, float y, double yaw) : car_(x, y, yaw) {}
  void ApplyPath(std::span<const double> x, std::span<const double> y) override {
    car_.ApplyPath(x, y);
  }
  void Tick() override { car_.Tick(); }
  float x() const override { return car_.x(); }
  float y() const override { return car_.y(); }
  double yaw() const override { return car_.yaw(); }
  float speed() const override { return car_.speed(); }
  std::span<const float> path_x() const override { return car_.path_x(); }
  std::span<const float> path_y() const override { return car_.path_y(); }

 private:
  EgoCar car_;
};

// True when the car of `row` was not on the road (or elsewhere) in the previous message: the
// first message after it was spawned or re-spawned.
bool JustSpawned(const Recording& rec, std::size_t k, const std::array<double, 7>& row) {
  if (row[6] < 0 || row[6] > 12) return false;
  if (k == 0) return true;
  for (const auto& prev : rec.messages[k - 1].sensor_fusion) {
    if (prev[0] != row[0]) continue;
    return prev[6] < 0 || prev[6] > 12 || std::hypot(row[1] - prev[1], row[2] - prev[2]) > 15;
  }
  return true;
}

}  // namespace

bool CheckReport::ok() const {
  if (rows.empty()) return false;
  return std::all_of(rows.begin(), rows.end(), [](const CheckRow& r) { return r.ok(); });
}

void CheckReport::Append(const CheckReport& other) {
  rows.insert(rows.end(), other.rows.begin(), other.rows.end());
  quirks.insert(quirks.end(), other.quirks.begin(), other.quirks.end());
}

double DigitsOff(double value, double recorded) {
  const float f = static_cast<float>(value);
  if (!std::isfinite(f) || !std::isfinite(recorded)) return std::numeric_limits<double>::infinity();
  const double diff = std::abs(recorded - static_cast<double>(f));
  if (diff == 0) return 0;
  const double unit = SeventhDigit(f);
  return unit > 0 ? diff / unit : std::numeric_limits<double>::infinity();
}

bool EqualAsPrinted(double value, double recorded) {
  // Half a unit of the 7th digit, widened by a hair for the decimal -> double parse of the
  // recorded text; either rounding of an exact tie passes (.NET rounds ties away from zero).
  return DigitsOff(value, recorded) <= 0.5 + kDigitSlack;
}

StatusOr<Recording> ParseRecording(std::string name, std::string_view input_text,
                                   std::string_view response_text) {
  Recording rec;
  rec.name = std::move(name);
  const auto inputs = Lines(input_text);
  const auto replies = Lines(response_text);
  if (inputs.size() != replies.size()) {
    return Status::Error(rec.name + ": " + std::to_string(inputs.size()) +
                         " telemetry lines but " + std::to_string(replies.size()) + " replies");
  }
  if (inputs.empty()) return Status::Error(rec.name + ": no telemetry lines");
  rec.messages.resize(inputs.size());
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    std::string error;
    if (!ParseMessage(inputs[i].second, &rec.messages[i], &error)) {
      return Status::Error(rec.name + ": input line " + std::to_string(inputs[i].first) + ": " +
                           error);
    }
    rec.replies.emplace_back(replies[i].second);
  }
  return rec;
}

StatusOr<std::vector<Recording>> LoadRecordings(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return Status::Error(dir + ": not a readable directory");
  std::vector<fs::path> inputs;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string f = e.path().filename().string();
    if (f.find("input-") != std::string::npos && e.path().extension() == ".json") {
      inputs.push_back(e.path());
    }
  }
  if (ec) return Status::Error(dir + ": " + ec.message());
  std::sort(inputs.begin(), inputs.end());
  auto read = [](const fs::path& p, std::string* out) {
    std::ifstream in(p, std::ios::binary);
    if (!in) return false;
    std::stringstream ss;
    ss << in.rdbuf();
    *out = ss.str();
    return true;
  };
  std::vector<Recording> out;
  for (const fs::path& input : inputs) {
    std::string f = input.filename().string();
    const std::size_t at = f.rfind("input-");
    fs::path response = input.parent_path() / (f.substr(0, at) + "response-" + f.substr(at + 6));
    if (!fs::exists(response, ec)) continue;  // a telemetry log without replies
    std::string in_text, resp_text;
    if (!read(input, &in_text)) return Status::Error(input.string() + ": cannot read");
    if (!read(response, &resp_text)) return Status::Error(response.string() + ": cannot read");
    // "Owner__repo__input-advanced.json" -> "Owner__repo__advanced".
    std::string name = f.substr(0, at) + f.substr(at + 6, f.size() - at - 6 - 5);
    auto rec = ParseRecording(name, in_text, resp_text);
    if (!rec.ok()) return rec.status();
    out.push_back(std::move(*rec));
  }
  if (out.empty()) {
    return Status::Error(dir + ": no recordings (pairs of *input-NAME.json and *response-NAME.json)");
  }
  return out;
}

// --- Protocol -------------------------------------------------------------------------------

CheckReport CheckProtocol(std::span<const Recording> recordings, plan::Planner& planner) {
  CheckRow parsed{"protocol: telemetry frame parsed", 0, 0, 0, 1e-9, "", {}};
  CheckRow answered{"protocol: valid control reply", 0, 0, 0, 1e-5, "m", {}};
  long not_ok_status = 0;
  wire::ParsedReply reply;
  std::string frame, control;
  for (const Recording& rec : recordings) {
    planner.Reset();
    for (std::size_t k = 0; k < rec.messages.size(); ++k) {
      const RecordedMessage& m = rec.messages[k];
      const std::string where = rec.name + " message " + std::to_string(k);
      frame = "42[\"telemetry\",";
      frame += m.json;
      frame += "]";
      const wire::ParsedFrame pf = wire::ParseFrame(frame);
      ++parsed.cases;
      ++answered.cases;
      if (pf.kind != wire::FrameKind::kTelemetry || !pf.error.empty()) {
        Fail(&parsed, where + ": " + wire::ToString(pf.kind) + " " + pf.error);
        continue;  // nothing to plan on: not answered either
      }
      // The parser must hand the planner the recorded values (only mph and degrees converted).
      const plan::Telemetry& t = pf.telemetry;
      double dev = 0;
      auto cmp = [&dev](double a, double b) {
        dev = std::max(dev, std::isfinite(a - b) ? std::abs(a - b) : INFINITY);
      };
      cmp(t.x, m.x);
      cmp(t.y, m.y);
      cmp(t.s, m.s);
      cmp(t.d, m.d);
      cmp(t.end_path_s, m.end_path_s);
      cmp(t.end_path_d, m.end_path_d);
      cmp(t.speed * units::kSimMpsToMph, m.speed_mph);
      cmp(std::remainder(t.yaw * units::kRadToDeg - m.yaw_deg, 360.0), 0.0);
      bool same_shape = t.previous_path_x.size() == m.path_x.size() &&
                        t.previous_path_y.size() == m.path_y.size() &&
                        t.sensor_fusion.size() == m.sensor_fusion.size();
      if (same_shape) {
        for (std::size_t i = 0; i < m.path_x.size(); ++i) {
          cmp(t.previous_path_x[i], m.path_x[i]);
          cmp(t.previous_path_y[i], m.path_y[i]);
        }
        for (std::size_t i = 0; i < m.sensor_fusion.size(); ++i) {
          const plan::SensorCar& c = t.sensor_fusion[i];
          const auto& r = m.sensor_fusion[i];
          cmp(c.id, r[0]);
          cmp(c.x, r[1]);
          cmp(c.y, r[2]);
          cmp(c.vx, r[3]);
          cmp(c.vy, r[4]);
          cmp(c.s, r[5]);
          cmp(c.d, r[6]);
        }
      }
      parsed.worst = std::max(parsed.worst, dev);
      if (!same_shape || !(dev <= parsed.tolerance)) {
        Fail(&parsed, where + Fmt(": parsed values differ from the recorded ones (%g)", dev));
      } else {
        ++parsed.passed;
      }

      const plan::PlanResult& result = planner.Plan(t);
      if (result.status != plan::PlanStatus::kOk) ++not_ok_status;
      const std::size_t written = wire::FormatControl(result.x, result.y, &control);
      wire::ParseReply(control, &reply);
      std::string why;
      double reply_dev = 0;
      if (reply.kind != wire::ReplyKind::kControl) {
        why = std::string("reply is ") + wire::ToString(reply.kind) + " " + reply.error;
      } else if (reply.x.size() != reply.y.size()) {
        why = "next_x and next_y differ in length";
      } else if (written != result.x.size() || result.x.size() != result.y.size() ||
                 reply.x.size() != result.x.size()) {
        why = Fmt("%zu points planned, %zu written, %zu parsed", result.x.size(), written,
                  reply.x.size());
      } else if (static_cast<int>(reply.x.size()) < plan::kMinPathPoints) {
        why = Fmt("only %zu points", reply.x.size());
      } else {
        for (std::size_t i = 0; i < reply.x.size(); ++i) {
          if (!std::isfinite(reply.x[i]) || !std::isfinite(reply.y[i])) {
            why = Fmt("point %zu is not finite", i);
            reply_dev = INFINITY;
            break;
          }
          reply_dev = std::max({reply_dev, std::abs(reply.x[i] - result.x[i]),
                                std::abs(reply.y[i] - result.y[i])});
        }
        if (why.empty() && !(reply_dev <= answered.tolerance)) {
          why = Fmt("parsed reply differs from the plan by %g m", reply_dev);
        }
      }
      answered.worst = std::max(answered.worst, reply_dev);
      if (why.empty()) {
        ++answered.passed;
      } else {
        Fail(&answered, where + ": " + why);
      }
    }
  }
  CheckReport report;
  report.rows = {parsed, answered};
  if (not_ok_status > 0) {
    report.quirks.push_back({"protocol", "planner status not ok (a valid reply was still sent)",
                             not_ok_status, "fallback or over budget; not a protocol failure"});
  }
  return report;
}

// --- Frenet -----------------------------------------------------------------------------------

FrenetFn ChordFrenetFn(std::shared_ptr<const World> world) {
  return [world = std::move(world)](double px, double py, double ox, double oy) {
    return world->chord->Convert(px, py, ox, oy);
  };
}

CheckReport CheckFrenet(std::span<const Recording> recordings, const FrenetFn& frenet) {
  CheckRow ego{"frenet: ego s,d", 0, 0, 0, kFrenetTolerance, "m", {}};
  CheckRow cars{"frenet: sensor_fusion s,d", 0, 0, 0, kFrenetTolerance, "m", {}};
  CheckRow end{"frenet: end_path s,d (ego as owner)", 0, 0, 0, kFrenetTolerance, "m", {}};
  long nan_rows = 0, end_quirk = 0, empty_paths = 0, spawn_rows = 0;
  double end_quirk_worst = 0, spawn_worst = 0;
  // The simulator reports float32; NaN is reported as 0 (sensor_fusion) by the simulator.
  auto dev = [](map::FrenetPoint f, double s, double d) {
    const double fs = static_cast<float>(f.s), fd = static_cast<float>(f.d);
    const double e = std::max(std::abs(fs - s), std::abs(fd - d));
    return std::isfinite(e) ? e : INFINITY;
  };
  for (const Recording& rec : recordings) {
    for (std::size_t k = 0; k < rec.messages.size(); ++k) {
      const RecordedMessage& m = rec.messages[k];
      const std::string where = rec.name + " message " + std::to_string(k);
      const map::FrenetPoint fe = frenet(m.x, m.y, m.x, m.y);
      const double e = dev(fe, m.s, m.d);
      ++ego.cases;
      ego.worst = std::max(ego.worst, e);
      if (e <= ego.tolerance) {
        ++ego.passed;
      } else {
        Fail(&ego, where + Fmt(": s,d %.4f,%.4f recomputed %.4f,%.4f", m.s, m.d, fe.s, fe.d));
      }

      for (const auto& row : m.sensor_fusion) {
        const map::FrenetPoint fc = frenet(row[1], row[2], row[1], row[2]);
        const double ec = dev(fc, row[5], row[6]);
        ++cars.cases;
        if (ec <= cars.tolerance) {
          ++cars.passed;
          cars.worst = std::max(cars.worst, ec);
        } else if (row[5] == 0 && row[6] == 0) {
          // The NaN -> 0 substitution (udacity-sim.md §8.6): documented, counted apart.
          ++nan_rows;
          ++cars.passed;
        } else if (JustSpawned(rec, k, row)) {
          // The message right after a spawn also reports the spawn velocity in the wrong unit
          // (§8.6): the physics has not run on the car yet, and its s, d do not come from the
          // reported x, y either. Counted apart, with the deviation.
          ++spawn_rows;
          spawn_worst = std::max(spawn_worst, ec);
          ++cars.passed;
        } else {
          cars.worst = std::max(cars.worst, ec);
          Fail(&cars, where + Fmt(": car %d s,d %.4f,%.4f recomputed %.4f,%.4f",
                                  static_cast<int>(row[0]), row[5], row[6], fc.s, fc.d));
        }
      }

      ++end.cases;
      if (m.path_x.empty()) {
        ++empty_paths;
        const double e0 = std::max(std::abs(m.end_path_s), std::abs(m.end_path_d));
        end.worst = std::max(end.worst, e0);
        if (e0 <= end.tolerance) {
          ++end.passed;
        } else {
          Fail(&end, where + ": empty path but end_path is not 0,0");
        }
        continue;
      }
      const double lx = m.path_x.back(), ly = m.path_y.back();
      const map::FrenetPoint fq = frenet(lx, ly, m.x, m.y);
      const double eq = dev(fq, m.end_path_s, m.end_path_d);
      end.worst = std::max(end.worst, eq);
      if (eq <= end.tolerance) {
        ++end.passed;
      } else {
        Fail(&end, where + Fmt(": end_path %.4f,%.4f recomputed %.4f,%.4f", m.end_path_s,
                               m.end_path_d, fq.s, fq.d));
      }
      // How much the quirk matters: the same point converted as its own owner.
      const double own = dev(frenet(lx, ly, lx, ly), m.end_path_s, m.end_path_d);
      if (own > kFrenetTolerance) {
        ++end_quirk;
        end_quirk_worst = std::max(end_quirk_worst, own);
      }
    }
  }
  CheckReport report;
  report.rows = {ego, cars, end};
  report.quirks.push_back({"frenet", "sensor_fusion NaN -> 0 (s = d = 0 reported)", nan_rows,
                           "udacity-sim.md §8.6; passes as the quirk"});
  report.quirks.push_back({"frenet", "just-spawned row: s,d not from the reported x,y",
                           spawn_rows, Fmt("up to %.3f m off", spawn_worst)});
  report.quirks.push_back(
      {"frenet", "end_path needs the ego-owner quirk (own-owner value off by > 0.01 m)",
       end_quirk, Fmt("up to %.3f m off without the quirk", end_quirk_worst)});
  report.quirks.push_back(
      {"frenet", "end_path of an empty previous_path reported as 0,0", empty_paths, ""});
  return report;
}

// --- Ego motion -------------------------------------------------------------------------------

EgoModelFactory SimulatorEgoModel() {
  return [](float x, float y, double yaw) -> std::unique_ptr<EgoModel> {
    return std::make_unique<SimulatorEgo>(x, y, yaw);
  };
}

CheckReport CheckEgoMotion(std::span<const Recording> recordings, const EgoModelFactory& model) {
  CheckRow path{"ego: previous_path after reply", 0, 0, 0, 0.5, "digits", {}};
  CheckRow pos{"ego: position x,y", 0, 0, 0, 0.5, "digits", {}};
  CheckRow speed{"ego: speed (mph) from point spacing", 0, 0, 0, kSpeedToleranceDigits,
                 "digits", {}};
  CheckRow yaw{"ego: yaw toward the second point", 0, 0, 0, kYawToleranceDeg, "deg", {}};
  long settling = 0, splits = 0, speed_not_exact = 0;
  wire::ParsedReply reply;
  std::vector<double> prev_x, prev_y;
  for (const Recording& rec : recordings) {
    for (std::size_t k = 0; k + 1 < rec.messages.size(); ++k) {
      const RecordedMessage& m = rec.messages[k];
      const RecordedMessage& n = rec.messages[k + 1];
      const std::string where = rec.name + " message " + std::to_string(k + 1);
      ++path.cases;
      ++pos.cases;
      wire::ParseReply(rec.replies[k], &reply);
      const long c = static_cast<long>(reply.x.size()) - static_cast<long>(n.path_x.size());
      if (reply.kind != wire::ReplyKind::kControl || c < 1) {
        const std::string why =
            reply.kind != wire::ReplyKind::kControl
                ? "reply " + std::to_string(k) + " is not a control: " + reply.error
                : "no consumed count (" + std::to_string(c) + ")";
        Fail(&path, where + ": " + why);
        Fail(&pos, where + ": " + why);
        continue;
      }
      const bool from_rest = m.path_x.empty();  // the first move from the start pose
      if (from_rest) {
        ++settling;
      } else {
        ++speed.cases;
      }
      if (c >= 2) ++yaw.cases;  // yaw points from the pre-tick position: needs a move before
      bool path_ok = true, pos_ok = true, speed_ok = true, yaw_ok = true;
      std::string path_why, pos_why, speed_why, yaw_why;
      for (long l_old = 0; l_old < c; ++l_old) {
        ++splits;
        std::unique_ptr<EgoModel> ego =
            model(static_cast<float>(m.x), static_cast<float>(m.y), m.yaw_deg / units::kRadToDeg);
        ego->ApplyPath(m.path_x, m.path_y);
        for (long i = 0; i < l_old; ++i) ego->Tick();
        ego->ApplyPath(reply.x, reply.y);
        for (long i = l_old; i < c; ++i) ego->Tick();

        const auto px = ego->path_x(), py = ego->path_y();
        double worst = 0;
        if (px.size() != n.path_x.size()) {
          worst = INFINITY;
          if (path_ok) {
            path_why = Fmt("l_old %ld: %zu points left, recorded %zu", l_old, px.size(),
                           n.path_x.size());
          }
        } else {
          for (std::size_t i = 0; i < px.size(); ++i) {
            worst = std::max({worst, DigitsOff(px[i], n.path_x[i]), DigitsOff(py[i], n.path_y[i])});
          }
          if (worst > path.tolerance + kDigitSlack && path_ok) {
            path_why = Fmt("l_old %ld: a point is %.2f digits off", l_old, worst);
          }
        }
        if (std::isfinite(worst)) path.worst = std::max(path.worst, worst);
        if (!(worst <= path.tolerance + kDigitSlack)) path_ok = false;

        const double wp = std::max(DigitsOff(ego->x(), n.x), DigitsOff(ego->y(), n.y));
        pos.worst = std::max(pos.worst, wp);
        if (!(wp <= pos.tolerance + kDigitSlack)) {
          if (pos_ok) {
            pos_why = Fmt("l_old %ld: at %.4f,%.4f, recorded %.4f,%.4f", l_old, ego->x(),
                          ego->y(), n.x, n.y);
          }
          pos_ok = false;
        }

        if (!from_rest) {
          // Unity: the rigidbody's speed times the factor, in float.
          const double mph = ego->speed() * static_cast<float>(units::kSimMpsToMph);
          const double ws = DigitsOff(mph, n.speed_mph);
          speed.worst = std::max(speed.worst, ws);
          if (ws > 0.5 + kDigitSlack) ++speed_not_exact;
          if (!(ws <= speed.tolerance + kDigitSlack)) {
            if (speed_ok) speed_why = Fmt("l_old %ld: %.7g mph, recorded %.7g", l_old, mph,
                                          n.speed_mph);
            speed_ok = false;
          }
        }
        if (c >= 2) {
          const double wy =
              std::abs(std::remainder(ego->yaw() * units::kRadToDeg - n.yaw_deg, 360.0));
          yaw.worst = std::max(yaw.worst, wy);
          if (!(wy <= yaw.tolerance)) {
            if (yaw_ok)
              yaw_why = Fmt("l_old %ld: %.4f deg, recorded %.4f", l_old,
                            ego->yaw() * units::kRadToDeg, n.yaw_deg);
            yaw_ok = false;
          }
        }
      }
      const std::string consumed = Fmt(" (%ld consumed)", c);
      if (path_ok) ++path.passed; else Fail(&path, where + consumed + ": " + path_why);
      if (pos_ok) ++pos.passed; else Fail(&pos, where + consumed + ": " + pos_why);
      if (!from_rest) {
        if (speed_ok) ++speed.passed; else Fail(&speed, where + consumed + ": " + speed_why);
      }
      if (c >= 2) {
        if (yaw_ok) ++yaw.passed; else Fail(&yaw, where + consumed + ": " + yaw_why);
      }
    }
  }
  CheckReport report;
  report.rows = {path, pos, speed, yaw};
  report.quirks.push_back({"ego", "first move from the start pose: speed includes settling",
                           settling, "reported speed not compared"});
  report.quirks.push_back({"ego", "speed not bit-exact (PhysX velocity rounding), split cases",
                           speed_not_exact, "within the speed tolerance"});
  report.quirks.push_back({"ego", "latency splits simulated (every l_old + l_new = consumed)",
                           splits, "all must reproduce the next message"});
  return report;
}

}  // namespace frenetic::sim
