#!/usr/bin/env bash
# Measures `frenetic serve` under abuse on loopback, for the README (measured, never asserted:
# tests/net/abuse_test.cc asserts the behaviour). Prints one line per figure.
#
#   scripts/serve-abuse.sh [--build-dir DIR] [--map FILE] [--seconds S] [--only NAMES]
#
#   --build-dir   a configured build with tests (default: build); frenetic and
#                 frenetic_serve_abuse are built there
#   --map         track file (default: the shared Udacity map, else the bundled track)
#   --seconds     length of each latency run (default: 20)
#   --only        a comma-separated subset of: none,flood,pipeline,huge,dense,churn,refuse,rss
#   --taskset S:C run the server on CPU list S and the clients on CPU list C (e.g. 0:1)
#   --rt          run the server's I/O and light planning threads and the timed client under
#                 SCHED_FIFO (chrt -f 1; the heavy planning threads and the abusers stay at the
#                 normal policy): on a machine that other work keeps busy, the figures are then
#                 the server's, not the machine's load
#
# Latency: a simulator-like client sends the telemetry of a recorded drive, one frame every
# 20 ms, and times each reply (send to last byte) while max_connections - 1 = 7 other
# connections flood (telemetry back to back), pipeline without reading, send 1 MiB frames,
# send the costliest frames within the limits, or churn (connect, plan once, close). refuse:
# 8 connections open, 200 more are timed from connect to the 503. rss: the server's resident
# set when fresh (after one connection) and after 500 connect / plan / close cycles.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$here/build"
map="$here/../shared/data/highway_map.csv"
seconds=20
only="none,flood,pipeline,huge,dense,churn,refuse,rss"
server_cpus=""
rt=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build-dir) build="${2:?}"; shift 2 ;;
    --map) map="${2:?}"; shift 2 ;;
    --seconds) seconds="${2:?}"; shift 2 ;;
    --only) only="${2:?}"; shift 2 ;;
    --taskset) server_cpus="${2:?}"; shift 2 ;;
    --rt) rt=1; shift ;;
    -h|--help) sed -n '2,25p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "serve-abuse.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done
[[ -f "$map" ]] || map="$here/config/tracks/frenetic_loop.csv"
cmake --build "$build" -j2 --target frenetic frenetic_serve_abuse >/dev/null
frenetic="$build/frenetic"
tool="$build/frenetic_serve_abuse"
tmp="$(mktemp -d)"
server_pid=""
cleanup() {
  if [[ -n "$server_pid" ]]; then kill -TERM "$server_pid" 2>/dev/null || true; fi
  rm -rf "$tmp"
}
trap cleanup EXIT

server_pin=()
client_pin=()
if [[ -n "$server_cpus" ]]; then
  server_pin=(taskset -c "${server_cpus%%:*}")
  client_pin=(taskset -c "${server_cpus#*:}")
fi
if [[ $rt -eq 1 ]]; then
  server_pin=(chrt -f 1 "${server_pin[@]}")
  client_pin=(chrt -f 1 "${client_pin[@]}")
fi

# The telemetry of a recorded drive (what a simulator would send), one frame per line: long
# enough that a latency run never wraps round to its start (a jump back in time and place).
"$frenetic" drive --map "$map" --seconds 150 --seed 3 --latency random --no-timing \
  --record "$tmp/drive.jsonl" >/dev/null
python3 - "$tmp/drive.jsonl" >"$tmp/frames.txt" <<'EOF'
import json, sys
for line in open(sys.argv[1]):
    j = json.loads(line)
    if j.get("type") == "exchange" and isinstance(j.get("telemetry"), dict):
        print('42["telemetry",' + json.dumps(j["telemetry"], separators=(",", ":")) + "]")
EOF

start_server() {
  : >"$tmp/serve.out"  # not the last server's port
  "${server_pin[@]}" "$frenetic" serve --map "$map" --port 0 --status-interval 0 "$@" \
    >"$tmp/serve.out" 2>"$tmp/serve.log" &
  server_pid=$!
  for _ in $(seq 200); do
    port="$(sed -n 's/.*listening on ws:\/\/127.0.0.1:\([0-9]*\).*/\1/p' "$tmp/serve.out")"
    [[ -n "$port" ]] && return 0
    sleep 0.05
  done
  echo "serve-abuse.sh: the server did not start: $(cat "$tmp/serve.log")" >&2
  exit 1
}
# SIGTERM: a background job of a non-interactive shell ignores SIGINT until serve handles it.
stop_server() {
  kill -TERM "$server_pid"
  wait "$server_pid" || true
  server_pid=""
}
rss_mb() { awk '/VmRSS/ {printf "%.1f", $2 / 1024}' "/proc/$server_pid/status"; }

echo "# $(date -u +%FT%TZ) $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)," \
  "map $(basename "$map"), rt $rt, taskset ${server_cpus:-none}"
for mode in ${only//,/ }; do
  case "$mode" in
    none|flood|pipeline|huge|dense|churn)
      start_server
      "${client_pin[@]}" "$tool" --port "$port" --mode "$mode" --abusers 7 --seconds "$seconds" \
        --frames "$tmp/frames.txt" || true
      stop_server ;;
    refuse)
      start_server --max-connections 8
      "${client_pin[@]}" "$tool" --port "$port" --mode refuse --abusers 8 --cycles 200 || true
      stop_server ;;
    rss)
      start_server
      "$tool" --port "$port" --mode cycles --cycles 1 --frames "$tmp/frames.txt" >/dev/null
      sleep 0.5
      fresh="$(rss_mb)"
      "$tool" --port "$port" --mode cycles --cycles 500 --frames "$tmp/frames.txt" >/dev/null
      sleep 0.5
      echo "{\"mode\":\"rss\",\"fresh_mb\":$fresh,\"after_500_cycles_mb\":$(rss_mb)}"
      stop_server ;;
    *) echo "serve-abuse.sh: unknown figure $mode" >&2; exit 2 ;;
  esac
done
