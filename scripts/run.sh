#!/usr/bin/env bash
# Installs what is missing, builds frenetic (Release) and runs it.
#   scripts/run.sh                 one lap of the bundled track with the search planner
#   scripts/run.sh ARGS...         frenetic ARGS... (for example: serve --map highway_map.csv)
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
ensure_packages "${BUILD_PACKAGES[@]}"
# Only what it runs, and the benchmark (the tests are scripts/test.sh's).
FRENETIC_TARGETS="frenetic frenetic_bench" configure_and_build
if [ $# -eq 0 ]; then
  set -- drive --laps 1
fi
exec "$BUILD_DIR/frenetic" "$@"
