#include "apps/commands.h"

namespace frenetic::apps {

void ExitWith(int code) {
  if (code != 0) throw CLI::RuntimeError(code);
}

}  // namespace frenetic::apps
