// Placeholder until the map commands land.
#include <cstdio>

#include "apps/commands.h"

namespace frenetic::apps {

void RegisterMapCheck(CLI::App& app) {
  auto* sub = app.add_subcommand("map-check", "(not built yet)");
  sub->callback([] { ExitWith(2); });
}
void RegisterTrack(CLI::App& app) {
  auto* sub = app.add_subcommand("track", "(not built yet)");
  sub->callback([] { ExitWith(2); });
}

}  // namespace frenetic::apps
