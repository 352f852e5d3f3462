// Placeholder until the drive command lands.
#include <cstdio>

#include "apps/commands.h"

namespace frenetic::apps {

void RegisterDrive(CLI::App& app) {
  auto* sub = app.add_subcommand("drive", "(not built yet)");
  sub->callback([] {
    std::fprintf(stderr, "frenetic drive: not built yet\n");
    ExitWith(2);
  });
}

}  // namespace frenetic::apps
