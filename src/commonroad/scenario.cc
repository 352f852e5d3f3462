#include "frenetic/commonroad/scenario.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <string>
#include <utility>

#include "commonroad/xml_source.h"

namespace frenetic::commonroad {

const Lanelet* Scenario::FindLanelet(int id) const {
  for (const Lanelet& l : lanelets) {
    if (l.id == id) return &l;
  }
  return nullptr;
}

const Obstacle* Scenario::FindObstacle(int id) const {
  for (const Obstacle& o : obstacles) {
    if (o.id == id) return &o;
  }
  return nullptr;
}

const PlanningProblem* Scenario::FindProblem(int id) const {
  for (const PlanningProblem& p : problems) {
    if (p.id == id) return &p;
  }
  return nullptr;
}

const TrafficSign* Scenario::FindSign(int id) const {
  for (const TrafficSign& s : signs) {
    if (s.id == id) return &s;
  }
  return nullptr;
}

namespace {

using pugi::xml_node;

// Time steps beyond this are rejected (10^8 steps of 0.1 s: 116 days), so step arithmetic stays
// far from int overflow.
constexpr int kMaxTimeStep = 100'000'000;

// A lanelet's two bounds run side by side: their ends lie at most kMaxBoundGap apart, and their
// lengths differ by at most that (a lane 15 m wide turning a full circle: 94 m) plus
// kBoundLengthSlack of the longer (the jitter of points sampled from a recording's map). A point
// off by a misplaced digit breaks one of these; a bound stretched that way would make the
// road's samples (every 2 m of it) run out of memory and time. Nor is a bound longer than
// kMaxBoundLength: CommonRoad's maps are local, a few kilometres across.
constexpr double kMaxBoundGap = 100.0;       // m
constexpr double kBoundLengthSlack = 0.1;    // of the longer bound's length
constexpr double kMaxBoundLength = 100'000;  // m

bool Named(const xml_node& n, const char* name) {
  return n.type() == pugi::node_element && std::string_view(n.name()) == name;
}

// Reads one document. Each method returns the first error; ids referenced before their target
// is read are resolved at the end (Resolve).
class Reader {
 public:
  explicit Reader(const XmlSource& src) : src_(src) {}

  Status Read(const pugi::xml_document& doc, Scenario* out);

 private:
  enum class RefKind { kLanelet, kSign };
  struct PendingRef {
    RefKind kind;
    int id;
    xml_node node;
  };

  Status ReadRoot(const xml_node& root, Scenario* out);
  Status ReadId(const xml_node& node, int* id) { return src_.AttrInt(node, "id", id); }
  Status ReadRef(const xml_node& node, RefKind kind, std::vector<int>* out);
  Status ReadPoint(const xml_node& node, Vec2* out);
  Status ReadBound(const xml_node& node, std::vector<Vec2>* points, LineMarking* marking);
  Status ReadLanelet(const xml_node& node, Lanelet* out);
  Status CheckSideBySide(const xml_node& node, const Lanelet& l);
  Status ReadSign(const xml_node& node, TrafficSign* out);
  Status ReadShapeElement(const xml_node& node, Shape* out);
  Status ReadShapeGroup(const xml_node& node, ShapeGroup* out);
  Status ReadValue(const xml_node& node, double* out);
  Status ReadInterval(const xml_node& node, Interval* out);
  Status ReadStepInterval(const xml_node& node, IntervalI* out);
  Status ReadStateTime(const xml_node& node, int* out);
  Status ReadState(const xml_node& node, bool need_velocity, State* out);
  Status ReadObstacle(const xml_node& node, ObstacleRole role, Obstacle* out);
  Status ReadOccupancySet(const xml_node& node, Obstacle* out);
  Status ReadGoal(const xml_node& node, GoalState* out);
  Status ReadProblem(const xml_node& node, PlanningProblem* out);
  Status Resolve(Scenario* out);

  const XmlSource& src_;
  std::vector<PendingRef> refs_;
};

Status Reader::Read(const pugi::xml_document& doc, Scenario* out) {
  const xml_node root = doc.document_element();
  if (!root) return Status::Error(src_.source() + ":1: document: no root element");
  if (std::string_view(root.name()) != "commonRoad") {
    return src_.Error(root, "the root element must be <commonRoad>");
  }
  FRENETIC_CR_TRY(ReadRoot(root, out));
  return Resolve(out);
}

Status Reader::ReadRoot(const xml_node& root, Scenario* out) {
  FRENETIC_CR_TRY(src_.AttrString(root, "commonRoadVersion", &out->version));
  if (out->version != "2020a") {
    return src_.Error(root, "commonRoadVersion '" + out->version.substr(0, 20) +
                                "' is not supported (2020a only)");
  }
  FRENETIC_CR_TRY(src_.AttrString(root, "benchmarkID", &out->benchmark_id));
  if (out->benchmark_id.empty()) return src_.Error(root, "attribute benchmarkID is empty");
  FRENETIC_CR_TRY(src_.AttrNumber(root, "timeStepSize", &out->dt));
  if (!(out->dt > 0)) return src_.Error(root, "timeStepSize must be positive");

  std::vector<Obstacle> dynamic;
  for (const xml_node& n : root.children()) {
    if (Named(n, "lanelet")) {
      FRENETIC_CR_TRY(ReadLanelet(n, &out->lanelets.emplace_back()));
    } else if (Named(n, "trafficSign")) {
      FRENETIC_CR_TRY(ReadSign(n, &out->signs.emplace_back()));
    } else if (Named(n, "staticObstacle")) {
      FRENETIC_CR_TRY(ReadObstacle(n, ObstacleRole::kStatic, &out->obstacles.emplace_back()));
    } else if (Named(n, "dynamicObstacle")) {
      FRENETIC_CR_TRY(ReadObstacle(n, ObstacleRole::kDynamic, &dynamic.emplace_back()));
    } else if (Named(n, "planningProblem")) {
      FRENETIC_CR_TRY(ReadProblem(n, &out->problems.emplace_back()));
    } else if (Named(n, "scenarioTags")) {
      for (const xml_node& tag : n.children()) {
        if (tag.type() == pugi::node_element) out->tags.emplace_back(tag.name());
      }
    }
  }
  for (Obstacle& o : dynamic) out->obstacles.push_back(std::move(o));
  for (Obstacle& o : out->obstacles) o.dt = out->dt;
  if (out->lanelets.empty()) return src_.Error(root, "no <lanelet>");
  if (out->problems.empty()) return src_.Error(root, "no <planningProblem>");
  return Status::Ok();
}

Status Reader::ReadRef(const xml_node& node, RefKind kind, std::vector<int>* out) {
  int id = 0;
  FRENETIC_CR_TRY(src_.AttrInt(node, "ref", &id));
  out->push_back(id);
  refs_.push_back({kind, id, node});
  return Status::Ok();
}

Status Reader::ReadPoint(const xml_node& node, Vec2* out) {
  FRENETIC_CR_TRY(src_.ChildNumber(node, "x", &out->x));
  return src_.ChildNumber(node, "y", &out->y);
}

Status Reader::ReadBound(const xml_node& node, std::vector<Vec2>* points, LineMarking* marking) {
  for (const xml_node& n : node.children()) {
    if (Named(n, "point")) {
      FRENETIC_CR_TRY(ReadPoint(n, &points->emplace_back()));
    } else if (Named(n, "lineMarking")) {
      *marking = ParseLineMarking(n.child_value());
    }
  }
  if (points->size() < 2) return src_.Error(node, "a bound needs at least two <point>s");
  if (CleanPolyline(*points).size() < 2) {
    return src_.Error(node, "a bound needs at least two distinct points");
  }
  return Status::Ok();
}

Status Reader::ReadLanelet(const xml_node& node, Lanelet* out) {
  out->line = src_.Line(node);
  FRENETIC_CR_TRY(ReadId(node, &out->id));
  bool left = false, right = false;
  for (const xml_node& n : node.children()) {
    if (Named(n, "leftBound")) {
      if (left) return src_.Error(n, "a second <leftBound>");
      left = true;
      FRENETIC_CR_TRY(ReadBound(n, &out->left, &out->left_marking));
    } else if (Named(n, "rightBound")) {
      if (right) return src_.Error(n, "a second <rightBound>");
      right = true;
      FRENETIC_CR_TRY(ReadBound(n, &out->right, &out->right_marking));
    } else if (Named(n, "predecessor")) {
      FRENETIC_CR_TRY(ReadRef(n, RefKind::kLanelet, &out->predecessors));
    } else if (Named(n, "successor")) {
      FRENETIC_CR_TRY(ReadRef(n, RefKind::kLanelet, &out->successors));
    } else if (Named(n, "adjacentLeft") || Named(n, "adjacentRight")) {
      std::vector<int> id;
      FRENETIC_CR_TRY(ReadRef(n, RefKind::kLanelet, &id));
      std::string dir;
      FRENETIC_CR_TRY(src_.AttrString(n, "drivingDir", &dir));
      if (dir != "same" && dir != "opposite") {
        return src_.Error(n, "drivingDir must be 'same' or 'opposite'");
      }
      std::optional<Adjacent>& adj = Named(n, "adjacentLeft") ? out->adjacent_left
                                                              : out->adjacent_right;
      if (adj) return src_.Error(n, std::string("a second <") + n.name() + ">");
      adj = Adjacent{id.front(), dir == "same"};
    } else if (Named(n, "laneletType")) {
      out->types.emplace_back(n.child_value());
    } else if (Named(n, "userOneWay")) {
      out->user_one_way.emplace_back(n.child_value());
    } else if (Named(n, "trafficSignRef")) {
      FRENETIC_CR_TRY(ReadRef(n, RefKind::kSign, &out->traffic_signs));
    }
  }
  if (!left) return src_.Error(node, "missing <leftBound>");
  if (!right) return src_.Error(node, "missing <rightBound>");
  return CheckSideBySide(node, *out);
}

Status Reader::CheckSideBySide(const xml_node& node, const Lanelet& l) {
  const auto m = [](double v) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.6g m", v);
    return std::string(text);
  };
  const double left = PolylineLength(l.left), right = PolylineLength(l.right);
  for (const double len : {left, right}) {
    if (!(len <= kMaxBoundLength)) {
      return src_.Error(node, "a bound " + m(len) + " long (at most " + m(kMaxBoundLength) +
                                  "; a point far off its line?)");
    }
  }
  const double start = Distance(l.left.front(), l.right.front());
  const double end = Distance(l.left.back(), l.right.back());
  const double slack = kMaxBoundGap + kBoundLengthSlack * std::max(left, right);
  if (!(start <= kMaxBoundGap && end <= kMaxBoundGap && std::abs(left - right) <= slack)) {
    return src_.Error(node, "its bounds do not run side by side (left " + m(left) +
                                " long, right " + m(right) + ", at most " + m(slack) +
                                " apart; their ends " + m(start) + " and " + m(end) +
                                " apart, at most " + m(kMaxBoundGap) + "): a point far off its line?");
  }
  return Status::Ok();
}

Status Reader::ReadSign(const xml_node& node, TrafficSign* out) {
  out->line = src_.Line(node);
  FRENETIC_CR_TRY(ReadId(node, &out->id));
  for (const xml_node& n : node.children()) {
    if (Named(n, "trafficSignElement")) {
      TrafficSignElement& e = out->elements.emplace_back();
      xml_node sign_id;
      FRENETIC_CR_TRY(src_.Child(n, "trafficSignID", &sign_id));
      e.sign_id = sign_id.child_value();
      for (const xml_node& v : n.children("additionalValue")) {
        e.additional_values.emplace_back(v.child_value());
      }
    } else if (Named(n, "position")) {
      xml_node point;
      FRENETIC_CR_TRY(src_.Child(n, "point", &point));
      FRENETIC_CR_TRY(ReadPoint(point, &out->position.emplace()));
    } else if (Named(n, "virtual")) {
      out->is_virtual = std::string_view(n.child_value()) == "true";
    }
  }
  if (out->elements.empty()) return src_.Error(node, "missing <trafficSignElement>");
  return Status::Ok();
}

Status Reader::ReadShapeElement(const xml_node& node, Shape* out) {
  if (Named(node, "rectangle")) {
    double length = 0, width = 0, orientation = 0;
    Vec2 center;
    FRENETIC_CR_TRY(src_.ChildNumber(node, "length", &length));
    FRENETIC_CR_TRY(src_.ChildNumber(node, "width", &width));
    if (!(length > 0) || !(width > 0)) {
      return src_.Error(node, "length and width must be positive");
    }
    if (const xml_node o = node.child("orientation")) FRENETIC_CR_TRY(src_.Number(o, &orientation));
    if (const xml_node c = node.child("center")) FRENETIC_CR_TRY(ReadPoint(c, &center));
    *out = Shape::Rectangle(length, width, center, orientation);
  } else if (Named(node, "circle")) {
    double radius = 0;
    Vec2 center;
    FRENETIC_CR_TRY(src_.ChildNumber(node, "radius", &radius));
    if (!(radius > 0)) return src_.Error(node, "radius must be positive");
    if (const xml_node c = node.child("center")) FRENETIC_CR_TRY(ReadPoint(c, &center));
    *out = Shape::Circle(radius, center);
  } else {  // polygon
    std::vector<Vec2> points;
    for (const xml_node& p : node.children("point")) {
      FRENETIC_CR_TRY(ReadPoint(p, &points.emplace_back()));
    }
    if (points.size() > 1 && points.front() == points.back()) points.pop_back();
    if (CleanPolyline(points).size() < 3) {
      return src_.Error(node, "a polygon needs at least three distinct points");
    }
    *out = Shape::Polygon(std::move(points));
  }
  return Status::Ok();
}

Status Reader::ReadShapeGroup(const xml_node& node, ShapeGroup* out) {
  for (const xml_node& n : node.children()) {
    if (Named(n, "rectangle") || Named(n, "circle") || Named(n, "polygon")) {
      FRENETIC_CR_TRY(ReadShapeElement(n, &out->shapes.emplace_back()));
    }
  }
  if (out->shapes.empty()) return src_.Error(node, "no <rectangle>, <circle> or <polygon>");
  return Status::Ok();
}

// <exact>, or the midpoint of <intervalStart>..<intervalEnd>.
Status Reader::ReadValue(const xml_node& node, double* out) {
  if (const xml_node exact = node.child("exact")) return src_.Number(exact, out);
  Interval interval;
  FRENETIC_CR_TRY(ReadInterval(node, &interval));
  *out = interval.Mid();
  return Status::Ok();
}

// <intervalStart>..<intervalEnd>, or an <exact> value as a one-point interval.
Status Reader::ReadInterval(const xml_node& node, Interval* out) {
  if (const xml_node exact = node.child("exact")) {
    FRENETIC_CR_TRY(src_.Number(exact, &out->start));
    out->end = out->start;
    return Status::Ok();
  }
  if (!node.child("intervalStart") && !node.child("intervalEnd")) {
    return src_.Error(node, "missing <exact> or <intervalStart>/<intervalEnd>");
  }
  FRENETIC_CR_TRY(src_.ChildNumber(node, "intervalStart", &out->start));
  FRENETIC_CR_TRY(src_.ChildNumber(node, "intervalEnd", &out->end));
  if (out->start > out->end) return src_.Error(node, "intervalStart is after intervalEnd");
  return Status::Ok();
}

// A time as steps: an <exact> step or <intervalStart>..<intervalEnd>, integers in
// [0, kMaxTimeStep].
Status Reader::ReadStepInterval(const xml_node& node, IntervalI* out) {
  Interval t;
  FRENETIC_CR_TRY(ReadInterval(node, &t));
  if (t.start < 0 || t.end > kMaxTimeStep || t.start != std::floor(t.start) ||
      t.end != std::floor(t.end)) {
    return src_.Error(node,
                      "time steps must be integers in [0, " + std::to_string(kMaxTimeStep) + "]");
  }
  *out = IntervalI{static_cast<int>(t.start), static_cast<int>(t.end)};
  return Status::Ok();
}

Status Reader::ReadStateTime(const xml_node& node, int* out) {
  xml_node time;
  FRENETIC_CR_TRY(src_.Child(node, "time", &time));
  const xml_node exact = time.child("exact");
  if (!exact) return src_.Error(time, "a state's time must be <exact> (an integer step)");
  FRENETIC_CR_TRY(src_.Integer(exact, out));
  if (*out < 0 || *out > kMaxTimeStep) {
    return src_.Error(exact, "time step out of range [0, " + std::to_string(kMaxTimeStep) + "]");
  }
  return Status::Ok();
}

Status Reader::ReadState(const xml_node& node, bool need_velocity, State* out) {
  FRENETIC_CR_TRY(ReadStateTime(node, &out->time_step));
  xml_node position;
  FRENETIC_CR_TRY(src_.Child(node, "position", &position));
  if (const xml_node point = position.child("point")) {
    FRENETIC_CR_TRY(ReadPoint(point, &out->position));
  } else {
    // An uncertain position (a region): its centroid.
    ShapeGroup region;
    FRENETIC_CR_TRY(ReadShapeGroup(position, &region));
    out->position = region.Centroid();
  }
  const struct {
    const char* name;
    std::optional<double>* field;
  } fields[] = {{"orientation", &out->orientation},   {"velocity", &out->velocity},
                {"acceleration", &out->acceleration}, {"yawRate", &out->yaw_rate},
                {"slipAngle", &out->slip_angle},      {"steeringAngle", &out->steering_angle}};
  for (const auto& f : fields) {
    if (const xml_node n = node.child(f.name)) FRENETIC_CR_TRY(ReadValue(n, &f.field->emplace()));
  }
  if (!out->orientation) return src_.Error(node, "missing <orientation>");
  if (need_velocity && !out->velocity) return src_.Error(node, "missing <velocity>");
  return Status::Ok();
}

Status Reader::ReadObstacle(const xml_node& node, ObstacleRole role, Obstacle* out) {
  out->line = src_.Line(node);
  out->role = role;
  FRENETIC_CR_TRY(ReadId(node, &out->id));
  xml_node type, shape, initial;
  FRENETIC_CR_TRY(src_.Child(node, "type", &type));
  out->type = type.child_value();
  FRENETIC_CR_TRY(src_.Child(node, "shape", &shape));
  FRENETIC_CR_TRY(ReadShapeGroup(shape, &out->shape));
  FRENETIC_CR_TRY(src_.Child(node, "initialState", &initial));
  FRENETIC_CR_TRY(ReadState(initial, /*need_velocity=*/false, &out->initial));
  if (role == ObstacleRole::kStatic) return Status::Ok();
  if (const xml_node occupancy = node.child("occupancySet")) {
    if (const xml_node trajectory = node.child("trajectory")) {
      return src_.Error(trajectory,
                        "both <trajectory> and <occupancySet> (a prediction is one or the other)");
    }
    return ReadOccupancySet(occupancy, out);
  }
  if (const xml_node trajectory = node.child("trajectory")) {
    int expected = out->initial.time_step + 1;
    for (const xml_node& n : trajectory.children("state")) {
      State& s = out->trajectory.emplace_back();
      FRENETIC_CR_TRY(ReadState(n, /*need_velocity=*/false, &s));
      if (s.time_step != expected) {
        return src_.Error(n, "time step " + std::to_string(s.time_step) + " where " +
                                 std::to_string(expected) +
                                 " was due (a trajectory's steps follow the initial state's "
                                 "one by one)");
      }
      ++expected;
    }
  }
  return Status::Ok();
}

// A set-based prediction: <occupancy> elements, each a <shape> (one or more shapes, the scenario's
// frame) over a <time> after the initial state's.
Status Reader::ReadOccupancySet(const xml_node& node, Obstacle* out) {
  out->prediction = ObstaclePrediction::kSetBased;
  for (const xml_node& n : node.children("occupancy")) {
    Occupancy& o = out->occupancies.emplace_back();
    xml_node shape, time;
    FRENETIC_CR_TRY(src_.Child(n, "shape", &shape));
    FRENETIC_CR_TRY(ReadShapeGroup(shape, &o.shape));
    FRENETIC_CR_TRY(src_.Child(n, "time", &time));
    FRENETIC_CR_TRY(ReadStepInterval(time, &o.time));
    if (o.time.start <= out->initial.time_step) {
      return src_.Error(time, "time step " + std::to_string(o.time.start) +
                                  " is not after the initial state's (" +
                                  std::to_string(out->initial.time_step) + ")");
    }
  }
  if (out->occupancies.empty()) return src_.Error(node, "no <occupancy>");
  return Status::Ok();
}

Status Reader::ReadGoal(const xml_node& node, GoalState* out) {
  out->line = src_.Line(node);
  if (const xml_node time = node.child("time")) {
    FRENETIC_CR_TRY(ReadStepInterval(time, &out->time.emplace()));
  }
  if (const xml_node position = node.child("position")) {
    for (const xml_node& n : position.children()) {
      if (Named(n, "lanelet")) {
        FRENETIC_CR_TRY(ReadRef(n, RefKind::kLanelet, &out->lanelets));
      } else if (Named(n, "rectangle") || Named(n, "circle") || Named(n, "polygon")) {
        FRENETIC_CR_TRY(ReadShapeElement(n, &out->shapes.emplace_back()));
      } else if (Named(n, "point")) {
        return src_.Error(n, "a goal position must be a region (shapes or lanelets), not a point");
      }
    }
    if (!out->HasPosition()) return src_.Error(position, "no shape or lanelet in <position>");
  }
  if (const xml_node v = node.child("velocity")) FRENETIC_CR_TRY(ReadInterval(v, &out->velocity.emplace()));
  if (const xml_node o = node.child("orientation")) {
    FRENETIC_CR_TRY(ReadInterval(o, &out->orientation.emplace()));
  }
  return Status::Ok();
}

Status Reader::ReadProblem(const xml_node& node, PlanningProblem* out) {
  out->line = src_.Line(node);
  FRENETIC_CR_TRY(ReadId(node, &out->id));
  xml_node initial;
  FRENETIC_CR_TRY(src_.Child(node, "initialState", &initial));
  FRENETIC_CR_TRY(ReadState(initial, /*need_velocity=*/true, &out->initial));
  for (const xml_node& n : node.children("goalState")) {
    FRENETIC_CR_TRY(ReadGoal(n, &out->goals.emplace_back()));
  }
  if (out->goals.empty()) return src_.Error(node, "missing <goalState>");
  return Status::Ok();
}

Status Reader::Resolve(Scenario* out) {
  // Duplicate ids: the error names the second element.
  const auto check_unique = [&](const char* what, auto& items) -> Status {
    std::set<int> seen;
    for (const auto& item : items) {
      if (!seen.insert(item.id).second) {
        return Status::Error(out->source + ":" + std::to_string(item.line) + ": " + what + " " +
                             std::to_string(item.id) + ": duplicate id");
      }
    }
    return Status::Ok();
  };
  FRENETIC_CR_TRY(check_unique("lanelet", out->lanelets));
  FRENETIC_CR_TRY(check_unique("trafficSign", out->signs));
  FRENETIC_CR_TRY(check_unique("obstacle", out->obstacles));
  FRENETIC_CR_TRY(check_unique("planningProblem", out->problems));

  std::set<int> lanelet_ids, sign_ids;
  for (const Lanelet& l : out->lanelets) lanelet_ids.insert(l.id);
  for (const TrafficSign& s : out->signs) sign_ids.insert(s.id);
  for (const PendingRef& r : refs_) {
    const bool lanelet = r.kind == RefKind::kLanelet;
    if (!(lanelet ? lanelet_ids : sign_ids).count(r.id)) {
      return src_.Error(r.node, "ref " + std::to_string(r.id) + " names no " +
                                    (lanelet ? "lanelet" : "trafficSign"));
    }
  }
  for (Lanelet& l : out->lanelets) {
    for (int sign_id : l.traffic_signs) {
      const std::optional<double> v = out->FindSign(sign_id)->MaxSpeed();
      if (v && (!l.speed_limit || *v < *l.speed_limit)) l.speed_limit = v;
    }
  }
  return Status::Ok();
}

// Scenario::origin: the lanelets' bounding box (the obstacles' and problems' positions when
// there are no lanelets), and every position moved by minus its centre, rounded to the
// kilometre, when the box reaches beyond kLocalFrameBeyond. Shapes of obstacles are in their own
// frames and stay; goal shapes and occupancies are in the scenario's and move.
void ToLocalFrame(Scenario* sc) {
  double lo_x = std::numeric_limits<double>::infinity(), lo_y = lo_x;
  double hi_x = -lo_x, hi_y = -lo_x;
  auto add = [&](Vec2 p) {
    lo_x = std::min(lo_x, p.x);
    hi_x = std::max(hi_x, p.x);
    lo_y = std::min(lo_y, p.y);
    hi_y = std::max(hi_y, p.y);
  };
  for (const Lanelet& l : sc->lanelets) {
    for (Vec2 p : l.left) add(p);
    for (Vec2 p : l.right) add(p);
  }
  if (sc->lanelets.empty()) {
    for (const Obstacle& o : sc->obstacles) add(o.initial.position);
    for (const PlanningProblem& p : sc->problems) add(p.initial.position);
  }
  if (!(hi_x >= lo_x && hi_y >= lo_y)) return;  // nothing placed
  const double reach =
      std::max({std::abs(lo_x), std::abs(hi_x), std::abs(lo_y), std::abs(hi_y)});
  if (!(reach > kLocalFrameBeyond)) return;
  const Vec2 o{1000.0 * std::round(0.5 * (lo_x + hi_x) / 1000.0),
               1000.0 * std::round(0.5 * (lo_y + hi_y) / 1000.0)};
  auto move = [&o](Vec2& p) { p = p - o; };
  for (Lanelet& l : sc->lanelets) {
    for (Vec2& p : l.left) move(p);
    for (Vec2& p : l.right) move(p);
  }
  for (TrafficSign& t : sc->signs) {
    if (t.position) move(*t.position);
  }
  for (Obstacle& ob : sc->obstacles) {
    move(ob.initial.position);
    for (State& st : ob.trajectory) move(st.position);
    for (Occupancy& occ : ob.occupancies) {
      for (Shape& shape : occ.shape.shapes) {
        move(shape.center);
        for (Vec2& v : shape.points) move(v);
      }
    }
  }
  for (PlanningProblem& p : sc->problems) {
    move(p.initial.position);
    for (GoalState& g : p.goals) {
      for (Shape& shape : g.shapes) {
        move(shape.center);
        for (Vec2& v : shape.points) move(v);
      }
    }
  }
  sc->origin = o;
}

}  // namespace

StatusOr<Scenario> ParseScenario(std::string_view xml, std::string_view source) {
  const XmlSource src(xml, source);
  pugi::xml_document doc;
  FRENETIC_CR_TRY(src.Parse(&doc));
  Scenario scenario;
  scenario.source = std::string(source);
  Reader reader(src);
  FRENETIC_CR_TRY(reader.Read(doc, &scenario));
  ToLocalFrame(&scenario);
  return scenario;
}

StatusOr<Scenario> LoadScenario(const std::string& path) {
  StatusOr<std::string> text = ReadXmlFile(path);
  if (!text.ok()) return text.status();
  return ParseScenario(*text, path);
}

}  // namespace frenetic::commonroad
