// Placeholder until the fidelity command lands.
#include <cstdio>

#include "apps/commands.h"

namespace frenetic::apps {

void RegisterFidelity(CLI::App& app) {
  auto* sub = app.add_subcommand("fidelity", "(not built yet)");
  sub->callback([] {
    std::fprintf(stderr, "frenetic fidelity: not built yet\n");
    ExitWith(2);
  });
}

}  // namespace frenetic::apps
