// The lanelet network of a scenario as a graph (lanelets by index, successors, neighbours on
// either side, inferred where a file leaves them out) and the route through it from a planning
// problem's start to its goal: what BuildRoad (road_builder.h) lays its road along.
#pragma once

#include <optional>
#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/planning_problem.h"
#include "frenetic/commonroad/scenario.h"

namespace frenetic::commonroad {

// The lanelet network by index, with what the search needs of each lanelet.
class Network {
 public:
  explicit Network(const Scenario& sc) : sc_(sc) {
    for (int i = 0; i < static_cast<int>(sc.lanelets.size()); ++i) {
      index_[sc.lanelets[i].id] = i;
      centre_.push_back(sc.lanelets[i].CenterLine());
      length_.push_back(PolylineLength(centre_.back()));
      polygon_.push_back(sc.lanelets[i].Polygon());
    }
    InferNeighbours();
  }
  int size() const { return static_cast<int>(sc_.lanelets.size()); }
  const Lanelet& at(int i) const { return sc_.lanelets[i]; }
  int Index(int id) const {
    const auto it = index_.find(id);
    return it == index_.end() ? -1 : it->second;
  }
  const std::vector<Vec2>& centre(int i) const { return centre_[i]; }
  double length(int i) const { return length_[i]; }
  const std::vector<Vec2>& polygon(int i) const { return polygon_[i]; }

  std::vector<int> Successors(int i) const { return Indices(at(i).successors); }
  std::vector<int> Predecessors(int i) const { return Indices(at(i).predecessors); }
  // The neighbour on one side (-1: left, +1: right) driven the same way, or -1: the one the
  // file gives, else one whose bound runs along this one's (InferNeighbours).
  int Beside(int i, int side) const {
    const std::optional<Adjacent>& a = side < 0 ? at(i).adjacent_left : at(i).adjacent_right;
    if (a.has_value()) return a->same_direction ? Index(a->id) : -1;
    return side < 0 ? inferred_left_[i] : inferred_right_[i];
  }
  // Every lanelet beside i (either side, any number of lanes over) with its lateral position
  // relative to i (left negative), i itself at 0.
  std::vector<std::pair<int, int>> CrossSection(int i) const {
    std::vector<std::pair<int, int>> out = {{i, 0}};
    for (int side : {-1, 1}) {
      std::set<int> seen = {i};
      int j = Beside(i, side), pos = side;
      while (j >= 0 && seen.insert(j).second) {
        out.push_back({j, pos});
        j = Beside(j, side);
        pos += side;
      }
    }
    return out;
  }
  double HeadingAt(int i, Vec2 p) const { return ProjectOntoPolyline(centre_[i], p).heading; }

 private:
  std::vector<int> Indices(const std::vector<int>& ids) const {
    std::vector<int> out;
    for (int id : ids) {
      if (const int j = Index(id); j >= 0) out.push_back(j);
    }
    return out;
  }

  // Some files leave out adjacency between lanelets that share a bound (DEU_Muc-2: two lanes
  // side by side, neither naming the other; US-101: an on-ramp along the right lane). A lanelet
  // without a neighbour on its left gets the one whose right bound runs along its left bound
  // (within kSharedBound of it for kSharedLength m or more, sampled every kSampleSpacing m: the
  // last stretch of a converging ramp will do; the same direction there) and that has no
  // neighbour on its right.
  // The halves of a split (lanelets with a common predecessor) are neighbours only when their
  // bounds meet at the fork (a lane widening into two): an exit ramp starts on top of the
  // straight half, and where it bends away its bound crosses the other's for a stretch.
  void InferNeighbours();
  // Whether lanelets i and j (indices) are successors of one lanelet.
  bool SharePredecessor(int i, int j) const {
    for (int a : at(i).predecessors) {
      for (int b : at(j).predecessors) {
        if (a == b) return true;
      }
    }
    return false;
  }

  const Scenario& sc_;
  std::vector<int> inferred_left_, inferred_right_;
  std::unordered_map<int, int> index_;
  std::vector<std::vector<Vec2>> centre_;
  std::vector<double> length_;
  std::vector<std::vector<Vec2>> polygon_;
};

// The lanelet holding the initial position whose heading is nearest the initial orientation,
// else the nearest within kMaxStartDistance (road_builder.h); -1 when none.
int StartLanelet(const Network& net, const State& init);
// The lanelets a goal position lies on: those it lists, and those holding a shape's centre (or
// overlapping the shape when none holds it).
std::set<int> GoalLanelets(const Network& net, const PlanningProblem& problem);
// Dijkstra from `start` to the nearest lanelet of `goals` (successor: its length; neighbour:
// kLaneChangeCost). Empty when none is reachable.
std::vector<int> RouteTo(const Network& net, int start, const std::set<int>& goals);
// The longest chain of successors from i (m), at most `budget` m, without revisiting.
double ChainLength(const Network& net, int i, double budget, std::set<int>& on_path);
// The successor of i that leads on longest (ties: the first), or -1.
int LongestSuccessor(const Network& net, int i, double budget);

}  // namespace frenetic::commonroad
