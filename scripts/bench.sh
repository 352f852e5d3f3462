#!/usr/bin/env bash
# Builds and runs the benchmark suite (bench/, google-benchmark).
#
#   scripts/bench.sh [--smoke] [--build-dir DIR] [--out FILE.json] [-- BENCHMARK_ARGS...]
#
#   --smoke        every benchmark once with a tiny --benchmark_min_time (a quick check that they
#                  all run; the times mean nothing). Exit status non-zero if one errors.
#   --build-dir    build directory (default: build-bench), configured as Release if needed
#   --out FILE     also write google-benchmark JSON there (e.g. a new baseline:
#                  --out bench/baselines/linux-x86_64-2core.json), then compare it with
#                  scripts/bench-compare.sh FILE
# Anything after -- goes to frenetic_bench (e.g. --benchmark_filter=BM_Plan/).
# Full runs pin to one core with taskset when available: the targets are per core.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$here/build-bench"
smoke=0
out=""
extra=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --smoke) smoke=1; shift ;;
    --build-dir) build="${2:?--build-dir needs a directory}"; shift 2 ;;
    --out) out="${2:?--out needs a file}"; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done

if [[ ! -f "$build/CMakeCache.txt" ]]; then
  cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build "$build" -j2 --target frenetic_bench
bin="$build/frenetic_bench"
[[ -x "$bin" ]] || { echo "bench.sh: $bin not built (is Google Benchmark installed?)" >&2; exit 1; }

args=()
if [[ $smoke -eq 1 ]]; then
  # Older google-benchmark takes seconds as a bare number; newer also accepts "1x" (iterations).
  args+=(--benchmark_min_time=0.001)
else
  args+=(--benchmark_counters_tabular=true)
fi
[[ -n "$out" ]] && args+=(--benchmark_out="$out" --benchmark_out_format=json)
pin=()
if [[ $smoke -eq 0 ]] && command -v taskset >/dev/null; then pin=(taskset -c 1); fi

log="$(mktemp)"
trap 'rm -f "$log"' EXIT
set +e
"${pin[@]}" "$bin" "${args[@]}" "${extra[@]}" 2>&1 | tee "$log"
rc=${PIPESTATUS[0]}
set -e
if grep -q "ERROR OCCURRED" "$log"; then
  echo "bench.sh: some benchmarks reported an error (see above)" >&2
  rc=1
fi
if [[ $smoke -eq 1 && $rc -eq 0 ]]; then
  echo "bench.sh --smoke: $(grep -c '^BM_' "$log") benchmarks ran"
fi
exit $rc
