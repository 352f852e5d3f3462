# Shared set-up for run.sh and test.sh: install missing Debian packages, configure, build.
# Sourced, not run. Idempotent: does nothing slow when everything is in place.
set -euo pipefail

FRENETIC_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${FRENETIC_BUILD_DIR:-$FRENETIC_ROOT/build}"
JOBS="${FRENETIC_JOBS:-$(nproc)}"

# Debian 12 packages the build needs.
BUILD_PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libnlopt-cxx-dev libceres-dev libboost-dev
  nlohmann-json3-dev libyaml-cpp-dev libcli11-dev libspdlog-dev libpugixml-dev zlib1g-dev
  libgtest-dev libgmock-dev libbenchmark-dev libopenmpi-dev openmpi-bin
)

log() { printf '[frenetic] %s\n' "$*" >&2; }

# ensure_packages PKG...: apt-get installs the ones that are missing (as root, or with sudo).
ensure_packages() {
  local missing=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  log "installing missing packages: ${missing[*]}"
  local sudo=()
  [ "$(id -u)" -eq 0 ] || sudo=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# configure_and_build [extra cmake args...]
# Builds the targets named in FRENETIC_TARGETS (space-separated), else everything configured.
configure_and_build() {
  local generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    log "configuring a Release build in $BUILD_DIR"
    # A unity build (each target's files compiled in batches of 8): a quarter less compile time.
    cmake -S "$FRENETIC_ROOT" -B "$BUILD_DIR" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_UNITY_BUILD=ON "$@" >/dev/null
  elif [ $# -gt 0 ]; then
    cmake -S "$FRENETIC_ROOT" -B "$BUILD_DIR" "$@" >/dev/null
  fi
  local targets=()
  for t in ${FRENETIC_TARGETS:-}; do targets+=(--target "$t"); done
  log "building ${FRENETIC_TARGETS:-everything} with $JOBS jobs"
  cmake --build "$BUILD_DIR" -j "$JOBS" "${targets[@]}"
}

# A separate build with AddressSanitizer + UndefinedBehaviorSanitizer (plus float-to-int overflow,
# which -fsanitize=undefined leaves out) of the library test suites
# (not the executable's end-to-end tests, the tuner or the benchmarks, which the Release run covers).
# The library at -O1, the tests' own files at -O0: they compile in about half the time, the
# sanitizers check the same code. With clang when there is one (test.sh installs it): its
# sanitizer builds take about a third less time than GCC's. A unity build, as in Release.
ASAN_TEST_MODULES=(yaml map traj cost plan wire net record sim eval drive report commonroad)
configure_and_build_asan() {
  local dir="$FRENETIC_ROOT/build-asan" generator=() targets=() compiler=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  command -v clang++ >/dev/null && compiler=(-DCMAKE_CXX_COMPILER=clang++)
  if [ ! -f "$dir/CMakeCache.txt" ]; then
    cmake -S "$FRENETIC_ROOT" -B "$dir" "${generator[@]}" "${compiler[@]}" -DCMAKE_BUILD_TYPE=None \
      -DCMAKE_UNITY_BUILD=ON \
      -DCMAKE_CXX_FLAGS="-O1 -g1" -DFRENETIC_SANITIZE=address,undefined,float-cast-overflow \
      -DFRENETIC_TEST_COMPILE_OPTIONS=-O0 \
      -DFRENETIC_BUILD_BENCHMARKS=OFF -DFRENETIC_WITH_MPI=OFF \
      -DFRENETIC_TEST_MODULES="$(IFS=';'; echo "${ASAN_TEST_MODULES[*]}")" \
      -DFRENETIC_SHARED_DIR="${SHARED_DIR:-$FRENETIC_ROOT/../shared}" >/dev/null
  fi
  for m in "${ASAN_TEST_MODULES[@]}"; do targets+=(--target "frenetic_${m}_tests"); done
  cmake --build "$dir" -j "$JOBS" "${targets[@]}"
}
