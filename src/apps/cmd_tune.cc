// Placeholder until the tune command lands.
#include <cstdio>

#include "apps/commands.h"

namespace frenetic::apps {

void RegisterTune(CLI::App& app) {
  auto* sub = app.add_subcommand("tune", "(not built yet)");
  sub->callback([] {
    std::fprintf(stderr, "frenetic tune: not built yet\n");
    ExitWith(2);
  });
}

}  // namespace frenetic::apps
