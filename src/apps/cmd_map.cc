// `frenetic map-check` (load a track, fit the reference line, print its diagnostics) and
// `frenetic track generate` (write a generated loop in the Udacity format).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>

#include "apps/commands.h"
#include "frenetic/json_text.h"
#include "frenetic/map/reference_line.h"
#include "frenetic/map/track.h"
#include "frenetic/map/track_generator.h"

namespace frenetic::apps {
namespace {

struct MapCheckArgs {
  std::string map;
  double max_s = 0;  // 0: computed from the closing segment
  bool json = false;
};

int RunMapCheck(const MapCheckArgs& args) {
  const std::string path = args.map.empty() ? map::DefaultTrackPath() : args.map;
  std::optional<double> max_s;
  if (args.max_s != 0) max_s = args.max_s;
  auto track = map::LoadTrack(path, max_s);
  if (!track.ok()) {
    std::fprintf(stderr, "frenetic map-check: %s\n", track.message().c_str());
    return 1;
  }
  const auto t0 = std::chrono::steady_clock::now();
  auto fitted = map::ReferenceLine::Fit(*track);
  const double fit_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!fitted.ok()) {
    std::fprintf(stderr, "frenetic map-check: %s\n", fitted.message().c_str());
    return 1;
  }
  const map::ReferenceLine& line = **fitted;

  double max_kappa = 0, max_heading_step = 0, max_dkappa_step = 0;
  const auto& samples = line.samples();
  for (size_t i = 0; i < samples.size(); ++i) {
    const map::RefSample& a = samples[i];
    const map::RefSample& b = samples[(i + 1) % samples.size()];
    max_kappa = std::max(max_kappa, std::abs(a.kappa));
    max_heading_step = std::max(
        max_heading_step, std::abs(std::remainder(b.heading - a.heading, 2 * std::numbers::pi)));
    max_dkappa_step = std::max(max_dkappa_step, std::abs(b.kappa - a.kappa));
  }
  static const double kOffsets[] = {-2, 0, 2, 6, 10, 14};
  double max_ds = 0, max_dd = 0, sum_ds = 0, sum_dd = 0;
  long count = 0;
  for (double d : kOffsets) {
    for (double s = 0; s < line.length(); s += 0.5) {
      const map::CartesianPose p = line.ToCartesian(s, d);
      const map::FrenetPoint f = line.ToFrenet(p.x, p.y);
      const double ds = std::abs(line.DiffS(f.s, s)), dd = std::abs(f.d - d);
      max_ds = std::max(max_ds, ds);
      max_dd = std::max(max_dd, dd);
      sum_ds += ds;
      sum_dd += dd;
      ++count;
    }
  }
  const double min_radius = max_kappa > 0 ? 1.0 / max_kappa : INFINITY;

  if (args.json) {
    nlohmann::json j = {
        {"map", path},
        {"waypoints", track->waypoints.size()},
        {"max_s_m", track->max_s},
        {"line_length_m", line.length()},
        {"samples", samples.size()},
        {"min_radius_m", min_radius},
        {"max_waypoint_distance_m", line.max_waypoint_distance()},
        {"max_map_s_difference_m", line.max_map_s_difference()},
        {"round_trip",
         {{"points", count},
          {"max_ds_m", max_ds},
          {"mean_ds_m", sum_ds / count},
          {"max_dd_m", max_dd},
          {"mean_dd_m", sum_dd / count}}},
        {"max_heading_step_rad", max_heading_step},
        {"max_kappa_step_per_m", max_dkappa_step},
        {"fit_seconds", fit_seconds},
    };
    std::printf("%s\n", JsonText(j).c_str());
    return 0;
  }
  std::printf("map                      %s\n", path.c_str());
  std::printf("waypoints                %zu\n", track->waypoints.size());
  std::printf("max_s                    %.3f m\n", track->max_s);
  std::printf("line length              %.3f m (%zu samples)\n", line.length(), samples.size());
  std::printf("minimum radius           %.1f m\n", min_radius);
  std::printf("max waypoint distance    %.4f m\n", line.max_waypoint_distance());
  std::printf("max s difference         %.4f m\n", line.max_map_s_difference());
  std::printf("round trip |ds| max/mean %.2e / %.2e m\n", max_ds, sum_ds / count);
  std::printf("round trip |dd| max/mean %.2e / %.2e m\n", max_dd, sum_dd / count);
  std::printf("max heading step         %.5f rad per sample\n", max_heading_step);
  std::printf("max curvature step       %.2e 1/m per sample\n", max_dkappa_step);
  std::printf("fit time                 %.3f s\n", fit_seconds);
  return 0;
}

int RunTrackGenerate(const map::TrackGeneratorOptions& options, const std::string& out) {
  auto track = map::GenerateTrack(options);
  if (!track.ok()) {
    std::fprintf(stderr, "frenetic track generate: %s\n", track.message().c_str());
    return 1;
  }
  // Round-trip through the parser so that a file we write is always a file we can read.
  const std::string text = map::FormatTrack(*track);
  auto reparsed = map::ParseTrack(text, out);
  if (!reparsed.ok()) {
    std::fprintf(stderr, "frenetic track generate: %s\n", reparsed.message().c_str());
    return 1;
  }
  std::ofstream file(out, std::ios::binary | std::ios::trunc);
  file << text;
  file.close();
  if (!file) {
    std::fprintf(stderr, "frenetic track generate: %s: cannot write\n", out.c_str());
    return 1;
  }
  std::printf("wrote %s: %zu waypoints, max_s %.3f m\n", out.c_str(), reparsed->waypoints.size(),
              reparsed->max_s);
  return 0;
}

}  // namespace

void RegisterMapCheck(CLI::App& app) {
  auto args = std::make_shared<MapCheckArgs>();
  auto* sub = app.add_subcommand(
      "map-check",
      "Load and validate a waypoint map, fit the smooth reference line and print its diagnostics\n"
      "(exit status 1 with a one-line error naming file and line on an invalid map).");
  sub->add_option("--map", args->map,
                  "Waypoint file, 'x y s dx dy' per line, space or comma separated (default: the "
                  "bundled track " +
                      map::DefaultTrackPath() + ")");
  sub->add_option("--max-s", args->max_s,
                  "Loop length in m overriding last s + closing chord (default: computed; "
                  "6945.554 for the Udacity map)")
      ->check(CLI::PositiveNumber);
  sub->add_flag("--json", args->json, "Print one JSON object instead of the table (default: off)");
  sub->callback([args] { ExitWith(RunMapCheck(*args)); });
}

void RegisterTrack(CLI::App& app) {
  auto* track = app.add_subcommand("track", "Track tools.");
  track->require_subcommand(1);
  auto options = std::make_shared<map::TrackGeneratorOptions>();
  auto out = std::make_shared<std::string>();
  auto* gen = track->add_subcommand("generate",
                                    "Write a deterministic closed, counter-clockwise highway loop "
                                    "in the Udacity waypoint format\n"
                                    "(star-shaped polar curve with seeded harmonics; see "
                                    "include/frenetic/map/track_generator.h).");
  gen->add_option("--length", options->length, "Loop length in m (default: 7000)");
  gen->add_option("--spacing", options->spacing,
                  "Mean waypoint spacing in m, jittered +-12% (default: 35)");
  gen->add_option("--min-radius", options->min_radius,
                  "Smallest radius of curvature in m; the tightest curve is about 2% above it "
                  "(default: 150)");
  gen->add_option("--seed", options->seed, "Random seed of the shape and spacing (default: 1)");
  gen->add_option("-o,--output", *out, "Output file (required)")->required();
  gen->callback([options, out] { ExitWith(RunTrackGenerate(*options, *out)); });
}

}  // namespace frenetic::apps
