#include "frenetic/commonroad/lanelet.h"

#include <algorithm>

namespace frenetic::commonroad {

LineMarking ParseLineMarking(std::string_view text) {
  if (text == "dashed") return LineMarking::kDashed;
  if (text == "solid") return LineMarking::kSolid;
  if (text == "broad_dashed") return LineMarking::kBroadDashed;
  if (text == "broad_solid") return LineMarking::kBroadSolid;
  if (text == "no_marking") return LineMarking::kNoMarking;
  return LineMarking::kUnknown;
}

const char* ToString(LineMarking marking) {
  switch (marking) {
    case LineMarking::kNone: return "none";
    case LineMarking::kUnknown: return "unknown";
    case LineMarking::kDashed: return "dashed";
    case LineMarking::kSolid: return "solid";
    case LineMarking::kBroadDashed: return "broad_dashed";
    case LineMarking::kBroadSolid: return "broad_solid";
    case LineMarking::kNoMarking: return "no_marking";
  }
  return "unknown";
}

std::vector<Vec2> Lanelet::CenterLine() const {
  std::vector<Vec2> l = left, r = right;
  if (l.size() != r.size()) {
    // Pairs of points are meaningful only for equal counts: pair points at equal arc-length
    // fractions instead.
    const int n = static_cast<int>(std::max(CleanLeft().size(), CleanRight().size()));
    l = ResamplePolyline(left, n);
    r = ResamplePolyline(right, n);
  }
  std::vector<Vec2> center;
  center.reserve(l.size());
  for (size_t i = 0; i < l.size(); ++i) center.push_back(0.5 * (l[i] + r[i]));
  return CleanPolyline(center);
}

std::vector<Vec2> Lanelet::Polygon() const {
  std::vector<Vec2> ring = left;
  ring.insert(ring.end(), right.rbegin(), right.rend());
  ring = CleanPolyline(ring);
  if (ring.size() > 1 && Distance(ring.front(), ring.back()) < 1e-9) ring.pop_back();
  return ring;
}

double Lanelet::Length() const { return PolylineLength(CenterLine()); }

}  // namespace frenetic::commonroad
