#include "frenetic/commonroad/road_builder.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <queue>
#include <set>
#include <unordered_map>
#include <utility>

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/road_area.h"
#include "frenetic/map/reference_line.h"
#include "commonroad/lanelet_network.h"

namespace frenetic::commonroad {

// Stations added between two border points at most (a segment of 2 km at kStationStep).
constexpr double kMaxStationParts = 1000;

LaneletStations ProjectLanelet(const Lanelet& l, const map::ReferenceLine& line) {
  std::vector<Vec2> left = l.left, right = l.right;
  if (left.size() != right.size()) {
    const int n = static_cast<int>(std::max(l.CleanLeft().size(), l.CleanRight().size()));
    left = ResamplePolyline(l.left, n);
    right = ResamplePolyline(l.right, n);
  }
  // Pairs of border points at most kStationStep apart on either side: each pair of
  // consecutive points with as many evenly spaced pairs between as the longer side needs.
  std::vector<Vec2> dense_left, dense_right;
  for (size_t i = 0; i < left.size(); ++i) {
    if (i > 0) {
      const double gap = std::max(Distance(left[i - 1], left[i]), Distance(right[i - 1], right[i]));
      // (At most kMaxStationParts: a hostile file's segment of 1e300 m stays cheap, and the
      // cast defined.)
      const int parts = std::isfinite(gap) ? static_cast<int>(std::min(
                                                 std::ceil(gap / kStationStep), kMaxStationParts))
                                           : 1;
      for (int q = 1; q < parts; ++q) {
        const double f = static_cast<double>(q) / parts;
        dense_left.push_back(left[i - 1] + f * (left[i] - left[i - 1]));
        dense_right.push_back(right[i - 1] + f * (right[i] - right[i - 1]));
      }
    }
    dense_left.push_back(left[i]);
    dense_right.push_back(right[i]);
  }
  left = std::move(dense_left);
  right = std::move(dense_right);
  LaneletStations out;
  double hint = NAN;
  for (size_t i = 0; i < left.size(); ++i) {
    const map::FrenetPoint fl = std::isfinite(hint) ? line.ToFrenet(left[i].x, left[i].y, hint)
                                                    : line.ToFrenet(left[i].x, left[i].y);
    const map::FrenetPoint fr = line.ToFrenet(right[i].x, right[i].y, fl.s);
    hint = fl.s;
    const double s = 0.5 * (fl.s + fr.s);
    if (!(fr.d - fl.d > kMinStationWidth) || (!out.s.empty() && !(s > out.s.back() + 1e-6))) continue;
    out.s.push_back(s);
    out.left.push_back(fl.d);
    out.right.push_back(fr.d);
  }
  return out;
}

namespace {

// m: where the skeleton moves to a neighbour lane (its own ends), the reference polyline leaves
// out this much on both sides of the junction, so that it crosses over gently.
constexpr double kJumpBlend = 25.0;
// m: lanelets of one lane this far apart along s (or closer) are one stretch of it.
constexpr double kLaneGap = 1.0;
// m: how far a lane goes on past an open end of the lanelet network (RoadArea's margin).
constexpr double kOpenEnd = RoadArea::kDefaultOpenEndMargin;
// m: lanes ending within kMapEndSlack of the map's last (or first) metre are the map's end and
// run on kMapRunOn m straight for the planner.
constexpr double kMapEndSlack = 10.0;
constexpr double kMapRunOn = 300.0;
// m: a lane farther than this from the lane on its left is apart from it there.
constexpr double kDetached = 0.5;
// m: a merging lanelet's taper ends where it is narrower (the planner's lane-end car is at
// least this wide, and would reach into the lane beside).
constexpr double kMinTaper = 0.5;

// A border given at stations (s increasing) read at s, linearly between them; false outside.
bool BorderAt(const std::vector<double>& st, const std::vector<double>& b, double s, double* out) {
  if (st.size() < 2 || !(s >= st.front() && s <= st.back())) return false;
  const size_t i = std::clamp<size_t>(std::upper_bound(st.begin(), st.end(), s) - st.begin(), 1,
                                      st.size() - 1);
  const double f = (s - st[i - 1]) / (st[i] - st[i - 1]);
  *out = b[i - 1] + f * (b[i] - b[i - 1]);
  return true;
}
// A lane profile's left (right: right) border at s, false outside its stations.
bool BorderAt(const map::LaneProfile& l, double s, bool right, double* out) {
  return BorderAt(l.s, right ? l.right : l.left, s, out);
}

std::string Where(const Scenario& sc, const PlanningProblem& p) {
  return sc.source + ": planning problem " + std::to_string(p.id) + ": ";
}

}  // namespace

StatusOr<BuiltRoad> BuildRoad(const Scenario& scenario, const PlanningProblem& problem) {
  const Network net(scenario);
  const std::string where = Where(scenario, problem);
  if (net.size() == 0) return Status::Error(where + "the scenario has no lanelets");
  const int start = StartLanelet(net, problem.initial);
  if (start < 0) {
    return Status::Error(where + "no lanelet within " + std::to_string(kMaxStartDistance) +
                         " m of the initial position");
  }
  // 1-2. The route.
  const std::set<int> goals = GoalLanelets(net, problem);
  bool any_position = false;
  for (const GoalState& g : problem.goals) any_position = any_position || g.HasPosition();
  std::vector<int> route;
  if (!goals.empty()) {
    route = RouteTo(net, start, goals);
    if (route.empty()) {
      return Status::Error(where + "no route from lanelet " + std::to_string(net.at(start).id) +
                           " to a goal lanelet");
    }
  } else if (any_position) {
    return Status::Error(where + "the goal position lies on no lanelet");
  } else {
    route = {start};
  }
  // 3. The route's cross-sections, each with the road's lateral position of its lanelets: a
  // section's positions are relative to its entry lanelet (where the route comes in), the next
  // section's entry continues the exit's lane.
  struct Section {
    std::vector<std::pair<int, int>> lanelets;  // lanelet, the road's lateral position
  };
  std::vector<Section> sections;
  {
    int base = 0, entry = route.front();
    std::vector<std::pair<int, int>> cs = net.CrossSection(entry);
    for (size_t r = 1; r <= route.size(); ++r) {
      const bool ends = r == route.size();
      const int prev = route[r - 1], cur = ends ? -1 : route[r];
      if (!ends && (net.Beside(prev, -1) == cur || net.Beside(prev, 1) == cur)) continue;
      // The section ends at `prev` (its exit).
      Section sec;
      int exit_pos = 0;
      for (const auto& [j, pos] : cs) {
        sec.lanelets.push_back({j, base + pos});
        if (j == prev) exit_pos = pos;
      }
      sections.push_back(std::move(sec));
      if (ends) break;
      base += exit_pos;
      entry = cur;
      cs = net.CrossSection(entry);
    }
  }
  auto position_in = [&](int section, int lanelet) {
    for (const auto& [j, pos] : sections[section].lanelets) {
      if (j == lanelet) return pos;
    }
    return INT_MIN;
  };
  // chain[i][j]: how many sections on lanelet j of section i continues by successors.
  std::vector<std::map<int, int>> chain(sections.size());
  for (int i = static_cast<int>(sections.size()) - 1; i >= 0; --i) {
    for (const auto& [j, pos] : sections[i].lanelets) {
      int best = 0;
      if (i + 1 < static_cast<int>(sections.size())) {
        for (int k : net.Successors(j)) {
          if (chain[i + 1].count(k)) best = std::max(best, chain[i + 1][k]);
        }
      }
      chain[i][j] = 1 + best;
    }
  }
  // The skeleton: the longest chain from the first section (of equals, the one nearest the
  // start's lane), on along it; where it ends before the last section, over to the next
  // section's longest chain nearest its lane. offset[k]: skeleton lanelet k's lateral position.
  std::vector<int> skeleton, offset;
  std::vector<bool> jump_before;
  auto pick = [&](int i, int near_pos, const std::vector<int>& among) {
    int best = -1, best_len = -1, best_off = INT_MAX;
    for (int j : among) {
      const auto it = chain[i].find(j);
      if (it == chain[i].end()) continue;
      const int off = std::abs(position_in(i, j) - near_pos);
      if (it->second > best_len || (it->second == best_len && off < best_off)) {
        best = j;
        best_len = it->second;
        best_off = off;
      }
    }
    return best;
  };
  for (int i = 0; i < static_cast<int>(sections.size()); ++i) {
    std::vector<int> all;
    for (const auto& [j, pos] : sections[i].lanelets) all.push_back(j);
    int next = -1;
    if (!skeleton.empty()) next = pick(i, offset.back(), net.Successors(skeleton.back()));
    const bool jump = next < 0;
    if (jump) next = pick(i, skeleton.empty() ? position_in(0, start) : offset.back(), all);
    skeleton.push_back(next);
    offset.push_back(position_in(i, next));
    jump_before.push_back(jump && i > 0);
  }
  // Road ahead of the goal and behind the start, for the horizon and the cars behind.
  std::set<int> used(skeleton.begin(), skeleton.end());
  for (double ahead = 0; ahead < kExtendAhead;) {
    const int j = LongestSuccessor(net, skeleton.back(), kExtendAhead);
    if (j < 0 || used.count(j)) break;
    ahead += net.length(j);
    skeleton.push_back(j);
    offset.push_back(offset.back());
    jump_before.push_back(false);
    used.insert(j);
  }
  for (double behind = 0; behind < kExtendBehind;) {
    const std::vector<int> preds = net.Predecessors(skeleton.front());
    if (preds.empty() || used.count(preds.front())) break;
    behind += net.length(preds.front());
    skeleton.insert(skeleton.begin(), preds.front());
    offset.insert(offset.begin(), offset.front());
    jump_before.insert(jump_before.begin(), false);
    used.insert(preds.front());
  }
  // The reference polyline: the skeleton's centre lines, crossing over gently at jumps.
  std::vector<map::ReferenceLine::Point> poly;
  for (size_t k = 0; k < skeleton.size(); ++k) {
    const std::vector<Vec2>& c = net.centre(skeleton[k]);
    const bool jump_after = k + 1 < skeleton.size() && jump_before[k + 1];
    const double len = net.length(skeleton[k]);
    double along = 0;
    for (size_t i = 0; i < c.size(); ++i) {
      if (i > 0) along += Distance(c[i], c[i - 1]);
      if (jump_before[k] && along < kJumpBlend && len > 2 * kJumpBlend) continue;
      if (jump_after && along > len - kJumpBlend && len > 2 * kJumpBlend) continue;
      poly.push_back({c[i].x, c[i].y});
    }
  }
  auto line = map::ReferenceLine::FitOpen(poly, map::ReferenceLine::Options(),
                                          where + "reference line");
  if (!line.ok()) return line.status();
  // 4. Lanes: every lanelet of the route's sections and of the extensions' cross-sections, at
  // its lateral position.
  struct Piece {
    int lanelet;
    LaneletStations st;
  };
  std::map<int, std::vector<Piece>> by_position;
  std::set<int> placed;
  auto place = [&](int j, int pos) {
    if (!placed.insert(j).second) return;
    LaneletStations st = ProjectLanelet(net.at(j), **line);
    if (st.s.size() >= 2) by_position[pos].push_back({j, std::move(st)});
  };
  for (const Section& sec : sections) {
    for (const auto& [j, pos] : sec.lanelets) place(j, pos);
  }
  // With each skeleton lanelet's cross-section, the opposite lanelet beside its leftmost one (a
  // two-way road): a lane driven the other way, at the next position to the left, its bounds
  // read in the road's direction.
  std::set<int> oncoming;
  std::vector<std::pair<int, int>> opposite;  // lanelet, lateral position
  for (size_t k = 0; k < skeleton.size(); ++k) {
    int leftmost = skeleton[k], left_pos = 0;
    for (const auto& [j, pos] : net.CrossSection(skeleton[k])) {
      place(j, offset[k] + pos);
      if (pos < left_pos) {
        leftmost = j;
        left_pos = pos;
      }
    }
    const std::optional<Adjacent>& a = net.at(leftmost).adjacent_left;
    if (a.has_value() && !a->same_direction) {
      opposite.push_back({net.Index(a->id), offset[k] + left_pos - 1});
    }
  }
  for (const auto& [o, pos] : opposite) {
    if (o < 0 || !placed.insert(o).second) continue;
    Lanelet reversed = net.at(o);
    reversed.left.assign(net.at(o).right.rbegin(), net.at(o).right.rend());
    reversed.right.assign(net.at(o).left.rbegin(), net.at(o).left.rend());
    LaneletStations st = ProjectLanelet(reversed, **line);
    if (st.s.size() < 2) continue;
    by_position[pos].push_back({o, std::move(st)});
    oncoming.insert(o);
  }
  // A lanelet merging into the road: a successor of one of its lanelets that is not part of it
  // but leads into it (the right half of a zipper merge, drawn converging onto the half the
  // reference follows, with no adjacency to it). It goes on the lane it comes from, clipped to
  // the lanes beside that one, up to where it is narrower than kMinTaper: the lane tapers off
  // where the merge really ends instead of ending with its last lanelet 20 m before.
  std::vector<std::pair<int, int>> merging;  // lanelet, lateral position
  for (const auto& [pos, pieces] : by_position) {
    for (const Piece& p : pieces) {
      for (int j : net.Successors(p.lanelet)) {
        if (placed.count(j) > 0) continue;
        const std::vector<int> next = net.Successors(j);
        if (std::any_of(next.begin(), next.end(), [&](int k) { return placed.count(k) > 0; })) {
          merging.push_back({j, pos});
        }
      }
    }
  }
  // The border of lateral position `pos` at s (right: its right one), false where it has none.
  const auto border_at = [&](int pos, double s, bool right, double* out) {
    const auto it = by_position.find(pos);
    if (it == by_position.end()) return false;
    for (const Piece& p : it->second) {
      if (BorderAt(p.st.s, right ? p.st.right : p.st.left, s, out)) return true;
    }
    return false;
  };
  for (const auto& [j, pos] : merging) {
    if (!placed.insert(j).second) continue;
    const LaneletStations st = ProjectLanelet(net.at(j), **line);
    LaneletStations kept;
    for (size_t i = 0; i < st.s.size(); ++i) {
      double left = st.left[i], right = st.right[i], b = 0;
      if (border_at(pos - 1, st.s[i], true, &b)) left = std::max(left, b);
      if (border_at(pos + 1, st.s[i], false, &b)) right = std::min(right, b);
      if (!(right - left >= kMinTaper)) break;
      kept.s.push_back(st.s[i]);
      kept.left.push_back(left);
      kept.right.push_back(right);
    }
    if (kept.s.size() >= 2) by_position[pos].push_back({j, std::move(kept)});
  }
  BuiltRoad out;
  std::vector<map::LaneProfile> lanes;
  std::vector<int> lane_pos;  // each lane's lateral position
  for (auto& [pos, pieces] : by_position) {
    std::sort(pieces.begin(), pieces.end(),
              [](const Piece& a, const Piece& b) { return a.st.s.front() < b.st.s.front(); });
    // Contiguous pieces make one lane; a gap starts another at the same position.
    map::LaneProfile lane;
    std::vector<int> ids;
    auto flush = [&, pos = pos] {  // (clang 14 cannot capture structured bindings)
      if (lane.s.size() >= 2) {
        // Open ends (a first lanelet without predecessors, a last one without successors) go on
        // kOpenEnd m, as the verdict's road area does: a car may start there with its rear
        // past the end of the map.
        // An oncoming lane's lanelets run the other way: their ends are where s begins.
        const bool other_way = oncoming.count(net.Index(ids.front())) > 0;
        lane.oncoming = other_way;
        const Lanelet& first_piece = net.at(net.Index(ids.front()));
        const Lanelet& last_piece = net.at(net.Index(ids.back()));
        if (kOpenEnd > 0 && (other_way ? first_piece.successors : first_piece.predecessors).empty()) {
          lane.s.insert(lane.s.begin(), lane.s.front() - kOpenEnd);
          lane.left.insert(lane.left.begin(), lane.left.front());
          lane.right.insert(lane.right.begin(), lane.right.front());
        }
        // Its end is a lane drop when its last lanelet leads nowhere or only into the road
        // (not an exit: a successor off the road).
        if (!other_way) {
          const std::vector<int> next = net.Successors(net.Index(ids.back()));
          lane.drops = std::all_of(next.begin(), next.end(),
                                   [&](int k) { return placed.count(k) > 0; });
        }
        if (kOpenEnd > 0 && (other_way ? last_piece.predecessors : last_piece.successors).empty()) {
          lane.s.push_back(lane.s.back() + kOpenEnd);
          lane.left.push_back(lane.left.back());
          lane.right.push_back(lane.right.back());
        }
        lanes.push_back(std::move(lane));
        lane_pos.push_back(pos);
        out.lane_lanelets.push_back(ids);
      }
      lane = map::LaneProfile();
      ids.clear();
    };
    for (const Piece& p : pieces) {
      if (!lane.s.empty() && p.st.s.front() > lane.s.back() + kLaneGap) flush();
      ids.push_back(net.at(p.lanelet).id);
      if (const auto& lim = net.at(p.lanelet).speed_limit; lim.has_value()) {
        lane.speed_limit = std::min(lane.speed_limit, *lim);
      }
      for (size_t i = 0; i < p.st.s.size(); ++i) {
        if (!lane.s.empty() && !(p.st.s[i] > lane.s.back() + 1e-6)) continue;
        lane.s.push_back(p.st.s[i]);
        lane.left.push_back(p.st.left[i]);
        lane.right.push_back(p.st.right[i]);
      }
    }
    flush();
  }
  // A lane lying apart from the lanes on its left (a gap wider than kDetached between them: an
  // on-ramp before it converges) is a lane only where it touches them: its longest stretch of
  // stations that do. Between the two, the road has no surface.
  for (size_t i = 0; i < lanes.size(); ++i) {
    map::LaneProfile& l = lanes[i];
    std::vector<char> touching(l.s.size(), 1);
    bool apart = false;
    for (size_t k = 0; k < l.s.size(); ++k) {
      double gap = std::numeric_limits<double>::infinity();
      bool beside = false;
      for (size_t j = 0; j < lanes.size(); ++j) {
        double right = 0;
        if (lane_pos[j] != lane_pos[i] - 1 || !BorderAt(lanes[j], l.s[k], true, &right)) continue;
        beside = true;
        gap = std::min(gap, std::abs(l.left[k] - right));
      }
      if (beside && gap > kDetached) {
        touching[k] = 0;
        apart = true;
      }
    }
    if (!apart) continue;
    size_t best_from = 0, best_len = 0;
    for (size_t k = 0; k < l.s.size();) {
      size_t e = k;
      while (e < l.s.size() && touching[e]) ++e;
      if (e - k > best_len) {
        best_from = k;
        best_len = e - k;
      }
      k = e + 1;
    }
    map::LaneProfile kept;
    kept.speed_limit = l.speed_limit;
    kept.oncoming = l.oncoming;
    kept.drops = l.drops;
    for (size_t k = best_from; k < best_from + best_len; ++k) {
      kept.s.push_back(l.s[k]);
      kept.left.push_back(l.left[k]);
      kept.right.push_back(l.right[k]);
    }
    l = std::move(kept);
  }
  for (size_t i = lanes.size(); i-- > 0;) {
    if (lanes[i].s.size() >= 2) continue;
    lanes.erase(lanes.begin() + i);
    lane_pos.erase(lane_pos.begin() + i);
    out.lane_lanelets.erase(out.lane_lanelets.begin() + i);
  }
  // Where the map itself ends (every lane that reaches the road's last metres), the lanes run on
  // straight for the planner's horizons: the map's end is not a wall it must stop at, and a run
  // ends at the goal (the verdict still holds the ego to the lanelets up to there). Likewise
  // before the map's start.
  double first = std::numeric_limits<double>::infinity(), last = -first;
  for (const map::LaneProfile& l : lanes) {
    first = std::min(first, l.s.front());
    last = std::max(last, l.s.back());
  }
  // A problem whose goals are times only is met by staying on the map until then: its lanes end
  // at a wall at the map's end (the verdict closes the network's ends). A goal with a position
  // lies on the map, and the run ends there: the run-on stays open.
  bool time_only = true;
  for (const GoalState& g : problem.goals) time_only = time_only && !g.HasPosition();
  for (map::LaneProfile& l : lanes) {
    if (l.s.back() > last - kMapEndSlack) {
      l.drops = false;  // the map's end, not a lane's
      if (time_only) l.wall = l.s.back();
      l.s.push_back(l.s.back() + kMapRunOn);
      l.left.push_back(l.left.back());
      l.right.push_back(l.right.back());
    }
    if (l.s.front() < first + kMapEndSlack) {
      l.s.insert(l.s.begin(), l.s.front() - kMapRunOn);
      l.left.insert(l.left.begin(), l.left.front());
      l.right.insert(l.right.begin(), l.right.front());
    }
  }
  out.map_end = last;
  auto road = map::Road::Make(*line, std::move(lanes), where + "road");
  if (!road.ok()) return road.status();
  out.road = *road;
  for (int i : route) out.route.push_back(net.at(i).id);
  for (int i : skeleton) out.skeleton.push_back(net.at(i).id);
  out.start_lanelet = net.at(start).id;
  return out;
}

}  // namespace frenetic::commonroad
