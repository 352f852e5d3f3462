// Reading a record (schema.h: `frenetic drive --record run.jsonl.gz`, `frenetic commonroad
// --record DIR`; JSON lines: one header, one line per exchange, an optional footer; plain text or
// gzip-compressed, told apart by the first byte, whatever the file's name) into compact columns
// for the HTML report (report/page.h).
//
// Units are the record's own, kept as written so the page can show what the simulator measured:
// positions in m (map frame: x east, y north), time in simulated s, ego yaw in degrees
// counter-clockwise from +x, speed in mph, acceleration m/s^2, jerk m/s^3, planning time ms.
// Absent optional values are NaN (doubles) or -1 (integer lanes).
#pragma once

#include <cstdint>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/status.h"

namespace frenetic::record {

// How much of the record is kept. The defaults keep a 10-lap drive (~25,000 exchanges) small
// enough to open in a browser in well under 3 s.
struct ReadOptions {
  // Candidates kept per cycle, best first (the winner is always kept on top of these). >= 1.
  int max_candidates = 8;
  // Cycles whose candidates are kept, spread evenly over the run. On top of these, up to as many
  // again for incidents (the cycle with an incident and the 5 before it) and as many again for
  // cycles where the winner's lane changes. >= 1.
  int max_candidate_cycles = 1500;
  // Keep every path_stride-th point of the path sent (and its last point). >= 1.
  int path_stride = 5;
  // Traffic farther than this from the ego (m) is dropped from the replay. > 0.
  double traffic_range = 250.0;
  // Warnings about skipped lines kept in RunData::warnings (all are counted). >= 0.
  int max_warnings = 20;

  // Ok, or a one-line message naming the first invalid field.
  Status Validate() const;
};

// A polyline or outline in the map frame, m.
struct Polyline {
  std::vector<double> x, y;
};

// The header line, the fields the page uses.
struct RecordHeader {
  int version = 0;
  std::string map, scenario, planner;
  std::int64_t seed = 0;
  double max_s = 0;         // m, track length (0 when absent)
  double lane_width = 4.0;  // m
  int lanes = 3;
  double car_length = 4.6, car_width = 2.4;  // m, every car's box
  // The road's centre line (d = 0), map frame, m; lanes lie to its right (d > 0).
  std::vector<double> center_x, center_y;
  std::string config_json = "null";  // header.config re-serialised as JSON (object or string)

  // A CommonRoad run's record (`frenetic commonroad --record`, commonroad/record.h): world is
  // "commonroad" (empty for a drive's record, which has none of the fields below).
  std::string world;
  int problem = -1;  // the planning problem's id
  double dt = 0;     // s per time step
  std::string prediction, vehicle;
  struct Lane {
    Polyline left, right;  // borders
  };
  std::vector<Lane> road_lanes;  // left to right
  struct Goal {
    Polyline outline;
    int step_lo = -1, step_hi = -1;  // time window in steps, -1 when none
  };
  std::vector<Goal> goals;
};

// One cost term over the run: the winner's weight and unweighted value per exchange (NaN where
// that cycle did not report the term).
struct TermColumn {
  std::string name;
  std::vector<double> weight, value;
};

// A count per exchange, e.g. the candidates rejected for one reason (0 where absent).
struct CountColumn {
  std::string name;
  std::vector<int> count;
};

struct CandidateCost {
  int term = 0;  // index into RunData::terms
  double weight = 0, value = 0;  // contribution = weight * value
};

struct Candidate {
  int lane = -1;
  double end_speed = 0;   // m/s
  double duration = 0;    // s
  double total_cost = 0;  // weighted sum
  bool checked = false, winner = false;
  std::string reject;     // the rejection reason, empty when not rejected
  std::vector<double> x, y;  // m, map frame
  std::vector<CandidateCost> costs;
};

// The candidates of one cycle, best first as recorded (a winner beyond max_candidates is kept).
struct CycleCandidates {
  int exchange = 0;  // index into the per-exchange columns
  int listed = 0;    // how many candidates the record listed for this cycle
  std::vector<Candidate> candidates;
};

struct Incident {
  int exchange = 0;  // index into the per-exchange columns
  double t = 0, s = 0, d = 0;
  int lane = -1;
  std::string kind;  // collision, speed, acceleration, jerk, lane, off_road, ...
  double value = 0;
};

// A record in columns: every per-exchange vector has size() entries; ragged data (path, traffic)
// uses offsets of size() + 1 entries into flat arrays.
struct RunData {
  RecordHeader header;

  std::vector<int> cycle;  // the record's "i"
  std::vector<double> t;   // simulated s
  std::vector<double> x, y, yaw_deg, speed_mph, s, d;
  std::vector<double> acc, jerk, gap, headway;  // simulator's measures; gap m, headway s
  std::vector<int> lane;                        // metrics.lane, else from d; -1 unknown
  std::vector<double> ms_total, winner_total_cost, refine_cost_before, refine_cost_after;
  std::vector<int> winner_lane, generated, scored, checked, feasible, refine_iterations;
  std::vector<std::string> status_names;  // distinct plan.status strings
  std::vector<int> status;                // index into status_names, -1 when absent
  std::vector<CountColumn> rejections;    // by reason, in order of first appearance
  std::vector<TermColumn> terms;          // winner's costs, in order of first appearance

  std::vector<int> path_offset;  // path sent, decimated by ReadOptions::path_stride
  std::vector<double> path_x, path_y;
  std::vector<int> traffic_offset;  // sensor_fusion within ReadOptions::traffic_range
  std::vector<int> traffic_id;
  std::vector<double> traffic_x, traffic_y, traffic_heading_deg;
  // Each car's footprint (m) where the record gives it (rows [id, x, y, vx, vy, s, d, length,
  // width, heading_deg]), else NaN; the heading then comes from the row's too.
  std::vector<double> traffic_length, traffic_width;

  std::vector<CycleCandidates> candidate_cycles;  // sorted by exchange
  std::vector<Incident> incidents;                // in record order

  bool has_footer = false;
  std::string footer_json = "null";  // footer.report re-serialised as JSON

  // How the reading went.
  int lines = 0;          // non-blank lines read
  int skipped_lines = 0;  // malformed or unusable lines skipped
  std::vector<std::string> warnings;  // "LINE N: why", at most ReadOptions::max_warnings

  int size() const { return static_cast<int>(t.size()); }
};

// Reads a record, plain or gzip. `source` names it in messages. Fails, with a one-line message,
// when there is no header line before the first exchange, no exchange at all, or on invalid
// options; a malformed or unusable line after the header is skipped with a warning naming its
// line number. Compressed data that ends early or is corrupt after some exchanges ends the
// record there, with a warning saying so.
StatusOr<RunData> ReadRecord(std::istream& in, std::string_view source,
                             const ReadOptions& options = {});

// As ReadRecord, from a file; a missing or unreadable file is an error naming it.
StatusOr<RunData> ReadRecordFile(const std::string& path, const ReadOptions& options = {});

}  // namespace frenetic::record
