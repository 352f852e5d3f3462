#!/usr/bin/env bash
# Builds the libFuzzer targets with clang in build-fuzz and runs them, side by side with two cores
# or more (FRENETIC_JOBS, default 2): the wire-protocol fuzzer and the CommonRoad readers'
# (scenario and solution files).
#   scripts/fuzz.sh [SECONDS]     run each for SECONDS (default 60); exit 0 when nothing was found
#   FRENETIC_FUZZ_SEED=N          libFuzzer seed (default 1, so CI runs are repeatable)
# Needs clang and libclang-rt-14-dev. Findings (crash-*, leak-*, timeout-*) land in build-fuzz/.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SECONDS_TO_RUN="${1:-60}"
BUILD="${FRENETIC_FUZZ_BUILD_DIR:-$ROOT/build-fuzz}"
JOBS="${FRENETIC_JOBS:-2}"
SHARED="${FRENETIC_SHARED_DIR:-$ROOT/../shared}"
case "$SECONDS_TO_RUN" in ''|*[!0-9]*) echo "usage: scripts/fuzz.sh [SECONDS]" >&2; exit 2 ;; esac
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (apt-get install clang)" >&2; exit 2; }

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
if [ ! -f "$BUILD/CMakeCache.txt" ]; then
  CXX=clang++ cmake -S "$ROOT" -B "$BUILD" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DFRENETIC_BUILD_FUZZERS=ON -DFRENETIC_BUILD_TESTS=OFF -DFRENETIC_BUILD_BENCHMARKS=OFF \
    -DFRENETIC_WITH_MPI=OFF >/dev/null
fi
cmake --build "$BUILD" -j "$JOBS" --target frame_parser_fuzz scenario_parser_fuzz

# Seeds: the frames of the protocol, and real telemetry when the recordings are present.
SEEDS="$BUILD/seeds/frame_parser"
CORPUS="$BUILD/corpus/frame_parser"
mkdir -p "$SEEDS" "$CORPUS"
printf '%s' '42["telemetry",null]' >"$SEEDS/null"
printf '%s' '42["manual",{}]' >"$SEEDS/manual"
printf '%s' '2' >"$SEEDS/ping"
printf '%s' '42["control",{"next_x":[909.5,910.1],"next_y":[1128.67,1128.7]}]' >"$SEEDS/control"
printf '%s' '42["telemetry",{"x":909.48,"y":1128.67,"yaw":0,"speed":0,"s":124.8336,"d":6.164833,"previous_path_x":[909.4925,909.4987],"previous_path_y":[1128.67,1128.67],"end_path_s":125.1455,"end_path_d":6.167528,"sensor_fusion":[[0,1056.788,1164.296,37.39919,15.43803,275.7777,5.999895],[1,775.8,1425.2,0,0,6719.219,-280.1494]]}]' >"$SEEDS/first"
REAL="$SHARED/realdata/telemetry/Moecker__sdc_path_planning__input-advanced.json"
if [ -f "$REAL" ]; then
  i=0
  while IFS= read -r line && [ $i -lt 8 ]; do
    printf '42["telemetry",%s]' "$line" >"$SEEDS/real_$i"
    i=$((i + 1))
  done < <(awk 'NR % 200 == 1' "$REAL")
fi
DICT="$BUILD/seeds/frame_parser.dict"
cat >"$DICT" <<'DICT_EOF'
"42"
"[\"telemetry\","
"[\"control\","
"null"
"\"x\":"
"\"y\":"
"\"yaw\":"
"\"speed\":"
"\"s\":"
"\"d\":"
"\"previous_path_x\":"
"\"previous_path_y\":"
"\"end_path_s\":"
"\"end_path_d\":"
"\"sensor_fusion\":"
"\"next_x\":"
"\"next_y\":"
"\"NaN\""
"1e999"
"-0"
DICT_EOF

cd "$BUILD"
FRAME_RUN=(./frame_parser_fuzz -seed="${FRENETIC_FUZZ_SEED:-1}" -max_total_time="$SECONDS_TO_RUN"
  -max_len=16384 -timeout=10 -rss_limit_mb=2048 -dict="$DICT" -print_final_stats=1 "$CORPUS" "$SEEDS")

# The CommonRoad readers: a hand-made scenario (every element they read) and solution, with the
# small solution files of the shared highD set when present (the scenarios are too long).
SEEDS="$BUILD/seeds/scenario_parser"
CORPUS="$BUILD/corpus/scenario_parser"
mkdir -p "$SEEDS" "$CORPUS"
cp "$ROOT"/tests/fuzz/seeds/scenario_parser/*.xml "$SEEDS/"
for f in "$SHARED"/commonroad/highD/*.solution.xml; do
  if [ -f "$f" ] && [ "$(wc -c <"$f")" -le 16384 ]; then cp "$f" "$SEEDS/"; fi
done
SCENARIO_RUN=(./scenario_parser_fuzz -seed="${FRENETIC_FUZZ_SEED:-1}" -max_total_time="$SECONDS_TO_RUN"
  -max_len=16384 -timeout=10 -rss_limit_mb=2048 -dict="$ROOT/tests/fuzz/seeds/scenario_parser/xml.dict"
  -print_final_stats=1 "$CORPUS" "$SEEDS")

# With two cores or more the fuzzers run side by side, each into its log, then the end of each
# log is printed (all of a log whose fuzzer found something); else one after the other.
if [ "$JOBS" -lt 2 ]; then
  "${FRAME_RUN[@]}"
  "${SCENARIO_RUN[@]}"
  exit 0
fi
"${FRAME_RUN[@]}" >frame_parser_fuzz.log 2>&1 &
frame_pid=$!
"${SCENARIO_RUN[@]}" >scenario_parser_fuzz.log 2>&1 &
scenario_pid=$!
frame_status=0
scenario_status=0
wait "$frame_pid" || frame_status=$?
wait "$scenario_pid" || scenario_status=$?
for run in "frame_parser_fuzz $frame_status" "scenario_parser_fuzz $scenario_status"; do
  set -- $run
  echo "== $1 (exit $2; the whole log: $BUILD/$1.log)"
  if [ "$2" -eq 0 ]; then tail -n 12 "$1.log"; else cat "$1.log"; fi
done
[ "$frame_status" -eq 0 ] && [ "$scenario_status" -eq 0 ]
