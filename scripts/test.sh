#!/usr/bin/env bash
# Installs what is missing, builds frenetic with its tests, and runs every test.
#   scripts/test.sh [--shared DIR]     DIR holds data/highway_map.csv and realdata/ (default ../shared)
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
SHARED_DIR="$FRENETIC_ROOT/../shared"
while [ $# -gt 0 ]; do
  case "$1" in
    --shared) SHARED_DIR="$2"; shift 2 ;;
    *) echo "usage: scripts/test.sh [--shared DIR]" >&2; exit 2 ;;
  esac
done
SHARED_DIR="$(cd "$SHARED_DIR" 2>/dev/null && pwd || echo "$SHARED_DIR")"

TEST_PACKAGES=(python3 python3-websockets clang libclang-rt-14-dev)
ensure_packages "${BUILD_PACKAGES[@]}" "${TEST_PACKAGES[@]}"
configure_and_build -DFRENETIC_BUILD_TESTS=ON -DFRENETIC_SHARED_DIR="$SHARED_DIR"

log "running the test suite"
cd "$BUILD_DIR"
ctest --output-on-failure -j "$JOBS" --timeout 600
