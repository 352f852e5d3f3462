#include "frenetic/map/track.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace frenetic::map {
namespace {

constexpr double kNormalTolerance = 1e-3;
// Two waypoints closer than this are the same point: the line through them has no direction.
constexpr double kDuplicateDistance = 1e-6;
// s is the distance along the road: a point farther from the previous row's than
// kChordRatio x the s between them plus kChordSlack (m) has a coordinate off (a fit through it
// would run thousands of kilometres out and back).
constexpr double kChordRatio = 2.0;
constexpr double kChordSlack = 10.0;

std::string Where(std::string_view source, int line) {
  return std::string(source) + ":" + std::to_string(line) + ": ";
}

// Splits a row on spaces, tabs and commas. Empty fields between two commas are kept so that
// "1,,2" is reported as malformed instead of silently becoming "1,2".
std::vector<std::string_view> SplitRow(std::string_view row) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (i < row.size()) {
    while (i < row.size() && is_space(row[i])) ++i;
    if (i >= row.size()) break;
    size_t j = i;
    while (j < row.size() && !is_space(row[j]) && row[j] != ',') ++j;
    fields.push_back(row.substr(i, j - i));
    i = j;
    while (i < row.size() && is_space(row[i])) ++i;
    if (i < row.size() && row[i] == ',') {
      ++i;
      // A trailing comma or ",," leaves an empty field.
      size_t k = i;
      while (k < row.size() && is_space(row[k])) ++k;
      if (k >= row.size() || row[k] == ',') fields.push_back(std::string_view());
      i = k;
    }
  }
  return fields;
}

bool ParseDouble(std::string_view field, double* out) {
  if (field.empty()) return false;
  if (field.front() == '+') field.remove_prefix(1);
  const char* end = field.data() + field.size();
  auto [ptr, ec] = std::from_chars(field.data(), end, *out);
  return ec == std::errc() && ptr == end;
}

std::string Fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

}  // namespace

StatusOr<Track> ParseTrack(std::string_view text, std::string_view source,
                           std::optional<double> max_s) {
  static const char* kNames[5] = {"x", "y", "s", "dx", "dy"};
  Track track;
  track.source = std::string(source);
  std::vector<int> line_of;  // 1-based line number of each waypoint, for messages
  int line_no = 0;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    std::string_view row = text.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    const auto fields = SplitRow(row);
    if (fields.empty()) {
      if (nl >= text.size()) break;
      continue;  // blank line
    }
    if (fields.size() != 5) {
      return Status::Error(Where(source, line_no) +
                           "malformed row: expected 5 fields x y s dx dy, got " +
                           std::to_string(fields.size()));
    }
    double v[5];
    for (int k = 0; k < 5; ++k) {
      if (!ParseDouble(fields[k], &v[k])) {
        return Status::Error(Where(source, line_no) + "malformed row: field " + kNames[k] +
                             " is not a number: '" + std::string(fields[k]) + "'");
      }
      if (!std::isfinite(v[k])) {
        return Status::Error(Where(source, line_no) + "field " + kNames[k] + " is not finite (" +
                             std::string(fields[k]) + ")");
      }
    }
    Waypoint w{v[0], v[1], v[2], v[3], v[4]};
    const double norm = std::hypot(w.dx, w.dy);
    if (std::abs(norm - 1.0) > kNormalTolerance) {
      return Status::Error(Where(source, line_no) + "normal (dx, dy) has length " + Fmt(norm) +
                           ", expected 1 +- 1e-3");
    }
    if (!track.waypoints.empty() && !(w.s > track.waypoints.back().s)) {
      return Status::Error(Where(source, line_no) + "s = " + Fmt(w.s) +
                           " does not increase (previous row s = " + Fmt(track.waypoints.back().s) +
                           ")");
    }
    if (!track.waypoints.empty()) {
      const Waypoint& p = track.waypoints.back();
      const double chord = std::hypot(w.x - p.x, w.y - p.y);
      if (chord > kChordRatio * (w.s - p.s) + kChordSlack) {
        return Status::Error(Where(source, line_no) + "point (" + Fmt(w.x) + ", " + Fmt(w.y) +
                             ") lies " + Fmt(chord) + " m from the previous row's, but s advances " +
                             Fmt(w.s - p.s) + " m (a coordinate off?)");
      }
    }
    track.waypoints.push_back(w);
    line_of.push_back(line_no);
    if (nl >= text.size()) break;
  }

  const int n = static_cast<int>(track.waypoints.size());
  if (n < 4) {
    return Status::Error(std::string(source) + ": " + std::to_string(n) +
                         " waypoints, need at least 4 to make a loop");
  }
  // Duplicates anywhere (not only neighbours): sort by x and compare within the tolerance band.
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return track.waypoints[a].x < track.waypoints[b].x; });
  for (int a = 0; a < n; ++a) {
    const Waypoint& wa = track.waypoints[order[a]];
    for (int b = a + 1; b < n; ++b) {
      const Waypoint& wb = track.waypoints[order[b]];
      if (wb.x - wa.x > kDuplicateDistance) break;
      if (std::hypot(wb.x - wa.x, wb.y - wa.y) <= kDuplicateDistance) {
        const int first = std::min(order[a], order[b]);
        const int second = std::max(order[a], order[b]);
        return Status::Error(Where(source, line_of[second]) + "duplicate point (" + Fmt(wb.x) +
                             ", " + Fmt(wb.y) + ") of line " + std::to_string(line_of[first]));
      }
    }
  }

  const Waypoint& first = track.waypoints.front();
  const Waypoint& last = track.waypoints.back();
  if (max_s.has_value()) {
    if (!std::isfinite(*max_s) || !(*max_s > last.s)) {
      return Status::Error(std::string(source) + ": max_s override " + Fmt(*max_s) +
                           " must be finite and greater than the last s " + Fmt(last.s));
    }
    track.max_s = *max_s;
  } else {
    track.max_s = last.s + std::hypot(first.x - last.x, first.y - last.y);
  }
  return track;
}

StatusOr<Track> LoadTrack(const std::string& path, std::optional<double> max_s) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open track file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return Status::Error(path + ": read error");
  return ParseTrack(buffer.str(), path, max_s);
}

std::string FormatTrack(const Track& track) {
  std::string out;
  char buf[160];
  for (const Waypoint& w : track.waypoints) {
    std::snprintf(buf, sizeof(buf), "%.17g %.17g %.17g %.17g %.17g\n", w.x, w.y, w.s, w.dx, w.dy);
    out += buf;
  }
  return out;
}

std::string DefaultTrackPath() { return FRENETIC_SOURCE_DIR "/config/tracks/frenetic_loop.csv"; }

}  // namespace frenetic::map
