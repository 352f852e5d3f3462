// Placeholder until the report command lands.
#include <cstdio>

#include "apps/commands.h"

namespace frenetic::apps {

void RegisterReport(CLI::App& app) {
  auto* sub = app.add_subcommand("report", "(not built yet)");
  sub->callback([] {
    std::fprintf(stderr, "frenetic report: not built yet\n");
    ExitWith(2);
  });
}

}  // namespace frenetic::apps
