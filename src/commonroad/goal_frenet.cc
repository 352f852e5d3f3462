#include "frenetic/commonroad/goal_frenet.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/road_builder.h"

namespace frenetic::commonroad {
namespace {

void AddBox(const map::ReferenceLine& line, const std::vector<Vec2>& pts, cost::GoalRegion* r) {
  r->s_lo = r->d_lo = std::numeric_limits<double>::infinity();
  r->s_hi = r->d_hi = -std::numeric_limits<double>::infinity();
  for (const Vec2& p : pts) {
    const map::FrenetPoint f = line.ToFrenet(p.x, p.y);
    r->s_lo = std::min(r->s_lo, f.s);
    r->s_hi = std::max(r->s_hi, f.s);
    r->d_lo = std::min(r->d_lo, f.d);
    r->d_hi = std::max(r->d_hi, f.d);
  }
}

// A goal rectangle: its long axis in the Frenet frame (the centre's s and d, the slope of d
// along s), the s range of its ends and the d half-width across it, the corners' s range for a
// wide one. Exact for a rectangle on a straight stretch of the line.
void AddRectangle(const map::ReferenceLine& line, const Shape& sh, cost::GoalRegion* r) {
  const bool long_axis = sh.length >= sh.width;
  const double along = long_axis ? sh.orientation : sh.orientation + 0.5 * 3.141592653589793;
  const double half_len = 0.5 * std::max(sh.length, sh.width), half_wid = 0.5 * std::min(sh.length, sh.width);
  const Vec2 u{std::cos(along), std::sin(along)};
  const map::FrenetPoint a = line.ToFrenet(sh.center.x - half_len * u.x, sh.center.y - half_len * u.y);
  const map::FrenetPoint b = line.ToFrenet(sh.center.x + half_len * u.x, sh.center.y + half_len * u.y);
  const map::FrenetPoint c = line.ToFrenet(sh.center.x, sh.center.y);
  const double ds = b.s - a.s;
  const double slope = std::abs(ds) > 1e-6 ? (b.d - a.d) / ds : 0.0;
  if (std::abs(slope) > 1.0) {  // turned across the road: its bounding box will do
    AddBox(line, sh.Vertices(), r);
    return;
  }
  r->s_ref = c.s;
  r->d_slope = slope;
  const double half_d = half_wid * std::sqrt(1 + slope * slope);  // across, measured along d
  r->d_lo = c.d - half_d;
  r->d_hi = c.d + half_d;
  const double spread = half_wid * std::abs(slope) / std::sqrt(1 + slope * slope);
  r->s_lo = std::min(a.s, b.s) - spread;
  r->s_hi = std::max(a.s, b.s) + spread;
}

// A goal lanelet (FrenetGoals).
void AddLanelet(const map::ReferenceLine& line, const Lanelet& l, cost::GoalRegion* r) {
  AddBox(line, l.Polygon(), r);
  const LaneletStations st = ProjectLanelet(l, line);
  const size_t n = st.s.size();
  if (n < 2) return;
  double s_mean = 0, c_mean = 0;
  for (size_t i = 0; i < n; ++i) {
    s_mean += st.s[i] / n;
    c_mean += 0.5 * (st.left[i] + st.right[i]) / n;
  }
  double sxx = 0, sxy = 0;
  for (size_t i = 0; i < n; ++i) {
    sxx += (st.s[i] - s_mean) * (st.s[i] - s_mean);
    sxy += (st.s[i] - s_mean) * (0.5 * (st.left[i] + st.right[i]) - c_mean);
  }
  const double slope = sxx > 1e-9 ? sxy / sxx : 0.0;
  double lo = -std::numeric_limits<double>::infinity(), hi = -lo;
  for (size_t i = 0; i < n; ++i) {
    const double off = slope * (st.s[i] - s_mean);
    lo = std::max(lo, st.left[i] - off);
    hi = std::min(hi, st.right[i] - off);
  }
  if (!(hi - lo >= kMinGoalBand) || !(std::abs(slope) <= 1.0)) return;
  r->s_ref = s_mean;
  r->d_slope = slope;
  r->d_lo = lo;
  r->d_hi = hi;
}

// The goal's orientation interval as a heading against the road's in the region (its s mid):
// a vehicle turned left of the road moves toward smaller d, so h = road - orientation.
void AddHeading(const map::ReferenceLine& line, const GoalState& g, cost::GoalRegion* r) {
  if (!g.orientation || !(g.orientation->end - g.orientation->start < 2 * 3.141592653589793)) {
    return;
  }
  const double road = line.At(0.5 * (r->s_lo + r->s_hi)).heading;
  const double half = 0.5 * (g.orientation->end - g.orientation->start);
  const double mid = WrapAngle(road - g.orientation->Mid());
  constexpr double kQuarter = 1.5;  // rad: headings beyond stay at its tangent
  r->h_lo = std::tan(std::clamp(mid - half, -kQuarter, kQuarter));
  r->h_hi = std::tan(std::clamp(mid + half, -kQuarter, kQuarter));
}

}  // namespace

double InsetBy(double lo, double hi, double margin) {
  return std::isfinite(lo) && std::isfinite(hi) ? std::min(margin, 0.25 * (hi - lo)) : 0.0;
}
cost::GoalRegion Inset(cost::GoalRegion r) {
  const double s = InsetBy(r.s_lo, r.s_hi, kInsetS), d = InsetBy(r.d_lo, r.d_hi, kInsetD);
  const double v = InsetBy(r.v_lo, r.v_hi, kInsetV), h = InsetBy(r.h_lo, r.h_hi, kInsetH);
  r.s_lo += s;
  r.s_hi -= s;
  r.d_lo += d;
  r.d_hi -= d;
  r.v_lo += v;
  r.v_hi -= v;
  r.h_lo += h;
  r.h_hi -= h;
  return r;
}

std::vector<FrenetGoal> FrenetGoals(const Scenario& sc, const PlanningProblem& p,
                                    const map::ReferenceLine& line) {
  std::vector<FrenetGoal> out;
  for (const GoalState& g : p.goals) {
    FrenetGoal base;
    if (g.time) {
      base.region.t_lo = g.time->start;
      base.region.t_hi = g.time->end;
      base.timed_lo = base.timed_hi = true;
    }
    if (g.velocity) {
      base.region.v_lo = g.velocity->start;
      base.region.v_hi = g.velocity->end;
    }
    if (!g.HasPosition()) {
      out.push_back(base);
      continue;
    }
    for (const Shape& sh : g.shapes) {
      FrenetGoal fg = base;
      if (sh.kind == Shape::Kind::kRectangle) {
        AddRectangle(line, sh, &fg.region);
        AddHeading(line, g, &fg.region);
        out.push_back(fg);
        continue;
      }
      std::vector<Vec2> pts = sh.Vertices();
      if (sh.kind == Shape::Kind::kCircle) {
        for (int i = 0; i < 8; ++i) {
          const double a = i * 0.25 * 3.141592653589793;
          pts.push_back({sh.center.x + sh.radius * std::cos(a), sh.center.y + sh.radius * std::sin(a)});
        }
      }
      AddBox(line, pts, &fg.region);
      AddHeading(line, g, &fg.region);
      out.push_back(fg);
    }
    for (int id : g.lanelets) {
      const Lanelet* l = sc.FindLanelet(id);
      if (l == nullptr) continue;
      FrenetGoal fg = base;
      AddLanelet(line, *l, &fg.region);
      AddHeading(line, g, &fg.region);
      out.push_back(fg);
    }
  }
  return out;
}

bool PassedEveryGoal(const std::vector<FrenetGoal>& goals, double s) {
  if (goals.empty()) return false;
  for (const FrenetGoal& g : goals) {
    if (!(std::isfinite(g.region.s_hi) && s > g.region.s_hi + kPassedMargin)) return false;
  }
  return true;
}

bool AcrossOpen(const map::Road& road, double start_s, const cost::GoalRegion& r) {
  if (!std::isfinite(r.s_lo) || !std::isfinite(r.s_hi) || road.num_lanes() < 1) return false;
  for (int l = 0; l < road.num_lanes(); ++l) {
    if (!(road.LaneBegin(l) <= start_s && road.LaneEnd(l) >= r.s_hi)) return false;
  }
  const map::Road::Span left = road.LaneAt(0, r.s_hi);
  const map::Road::Span right = road.LaneAt(road.num_lanes() - 1, r.s_hi);
  const double mid = 0.5 * (r.d_lo + r.d_hi) + r.d_slope * (r.s_hi - r.s_ref);
  return std::isfinite(mid) && mid >= left.left && mid <= right.right;
}

}  // namespace frenetic::commonroad
