#include "commonroad/lanelet_network.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <set>
#include <utility>

#include "frenetic/commonroad/road_builder.h"

namespace frenetic::commonroad {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

void Network::InferNeighbours() {
  constexpr double kSharedBound = 0.5;     // m
  constexpr double kSampleSpacing = 2.0;   // m
  constexpr double kSharedLength = 10.0;   // m of the bounds within kSharedBound of each other
  constexpr double kSameDirection = 0.35;  // rad
  const int n = size();
  inferred_left_.assign(n, -1);
  inferred_right_.assign(n, -1);
  for (int i = 0; i < n; ++i) {
    if (at(i).adjacent_left.has_value()) continue;
    const std::vector<Vec2> clean = at(i).CleanLeft();
    const double left_len = PolylineLength(clean);
    const int samples = std::max(2, static_cast<int>(std::ceil(left_len / kSampleSpacing)) + 1);
    const std::vector<Vec2> left = ResamplePolyline(clean, samples);
    const double spacing = left_len / (samples - 1);
    for (int j = 0; j < n && inferred_left_[i] < 0; ++j) {
      if (j == i || at(j).adjacent_right.has_value() || inferred_right_[j] >= 0) continue;
      const std::vector<Vec2> right = at(j).CleanRight();
      // The halves of a split only when side by side from the fork (a lane widening into two),
      // not when one bends off the other (the planner's lanes would jump across at the fork).
      if (SharePredecessor(i, j) && (left.empty() || right.empty() ||
                                     !(Distance(left.front(), right.front()) <= kSharedBound))) {
        continue;
      }
      const double len = PolylineLength(right);
      int shared = 0;
      bool opposite = false;
      for (const Vec2& p : left) {
        const PolylineProjection pr = ProjectOntoPolyline(right, p);
        if (pr.s < 0 || pr.s > len || std::abs(pr.d) > kSharedBound) continue;
        const double di = ProjectOntoPolyline(centre_[i], p).heading;
        if (std::abs(WrapAngle(di - pr.heading)) > kSameDirection) {
          opposite = true;
          break;
        }
        ++shared;
      }
      if (!opposite && shared * spacing >= kSharedLength) {
        inferred_left_[i] = j;
        inferred_right_[j] = i;
      }
    }
  }
}

int StartLanelet(const Network& net, const State& init) {
  int best = -1;
  double best_score = kInf;
  for (int i = 0; i < net.size(); ++i) {
    if (!PolygonContains(net.polygon(i), init.position)) continue;
    const double score =
        init.orientation ? std::abs(WrapAngle(net.HeadingAt(i, init.position) - *init.orientation))
                         : 0.0;
    if (score < best_score) {
      best_score = score;
      best = i;
    }
  }
  if (best >= 0) return best;
  double best_dist = kMaxStartDistance;
  for (int i = 0; i < net.size(); ++i) {
    const double d = PolygonDistance(net.polygon(i), init.position);
    if (d <= best_dist) {
      best_dist = d;
      best = i;
    }
  }
  return best;
}

// The lanelets a goal position lies on: those it lists, and those holding a shape's centre (or
// overlapping the shape when none holds it).
std::set<int> GoalLanelets(const Network& net, const PlanningProblem& problem) {
  std::set<int> out;
  for (const GoalState& g : problem.goals) {
    for (int id : g.lanelets) {
      if (const int i = net.Index(id); i >= 0) out.insert(i);
    }
    for (const Shape& shape : g.shapes) {
      const Vec2 c = shape.Centroid();
      bool found = false;
      for (int i = 0; i < net.size(); ++i) {
        if (PolygonContains(net.polygon(i), c)) {
          out.insert(i);
          found = true;
        }
      }
      if (found) continue;
      const std::vector<Vec2> v = shape.Vertices();
      for (int i = 0; i < net.size() && v.size() >= 3; ++i) {
        if (PolygonsOverlap(net.polygon(i), v)) out.insert(i);
      }
    }
  }
  return out;
}

// Dijkstra from `start` to the nearest lanelet of `goals` (successor: its length; neighbour:
// kLaneChangeCost). Empty when none is reachable.
std::vector<int> RouteTo(const Network& net, int start, const std::set<int>& goals) {
  std::vector<double> dist(net.size(), kInf);
  std::vector<int> from(net.size(), -1);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  dist[start] = 0;
  open.push({0.0, start});
  int reached = -1;
  while (!open.empty()) {
    const auto [d, i] = open.top();
    open.pop();
    if (d > dist[i]) continue;
    if (goals.count(i)) {
      reached = i;
      break;
    }
    // (The bindings by value: clang 14 cannot capture structured bindings.)
    auto relax = [&, d = d, i = i](int j, double cost) {
      if (j >= 0 && d + cost < dist[j]) {
        dist[j] = d + cost;
        from[j] = i;
        open.push({dist[j], j});
      }
    };
    for (int j : net.Successors(i)) relax(j, net.length(i));
    relax(net.Beside(i, -1), kLaneChangeCost);
    relax(net.Beside(i, 1), kLaneChangeCost);
  }
  std::vector<int> route;
  for (int i = reached; i >= 0; i = from[i]) route.push_back(i);
  std::reverse(route.begin(), route.end());
  return route;
}

// The longest chain of successors from i (m), at most `budget` m, without revisiting.
double ChainLength(const Network& net, int i, double budget, std::set<int>& on_path) {
  if (budget <= 0 || !on_path.insert(i).second) return 0;
  double best = 0;
  for (int j : net.Successors(i))
    best = std::max(best, ChainLength(net, j, budget - net.length(i), on_path));
  on_path.erase(i);
  return net.length(i) + best;
}

// The successor of i that leads on longest (ties: the first), or -1.
int LongestSuccessor(const Network& net, int i, double budget) {
  int best = -1;
  double best_len = -1;
  for (int j : net.Successors(i)) {
    std::set<int> on_path = {i};
    const double len = ChainLength(net, j, budget, on_path);
    if (len > best_len) {
      best_len = len;
      best = j;
    }
  }
  return best;
}

}  // namespace frenetic::commonroad
