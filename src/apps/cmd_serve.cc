// Placeholder until the serve command lands.
#include <cstdio>

#include "apps/commands.h"

namespace frenetic::apps {

void RegisterServe(CLI::App& app) {
  auto* sub = app.add_subcommand("serve", "(not built yet)");
  sub->callback([] {
    std::fprintf(stderr, "frenetic serve: not built yet\n");
    ExitWith(2);
  });
}

}  // namespace frenetic::apps
