#!/usr/bin/env bash
# Prints, for every benchmark of a google-benchmark JSON run, its time and the ratio to the
# committed baseline (bench/baselines/*.json), so that the cost of a change is visible.
#
#   scripts/bench-compare.sh NEW.json [BASELINE.json]
#
# BASELINE defaults to bench/baselines/linux-x86_64-2core.json. Ratios > 1 are slower. Rows
# marked "!" are more than --threshold (default 1.25) slower; the exit status is 0 unless the
# files cannot be read (a regression is reported, not failed: the machine may be loaded).
# Options: --threshold X, --metric real_time|cpu_time (default cpu_time: less sensitive to other
# processes on a shared machine), --counters (also compare p50_us / p99_us / cands_per_s).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
threshold=1.25
metric=cpu_time
counters=0
files=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --threshold) threshold="${2:?--threshold needs a value}"; shift 2 ;;
    --metric) metric="${2:?--metric needs real_time or cpu_time}"; shift 2 ;;
    --counters) counters=1; shift ;;
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "bench-compare: unknown option $1" >&2; exit 2 ;;
    *) files+=("$1"); shift ;;
  esac
done
if [[ ${#files[@]} -lt 1 || ${#files[@]} -gt 2 ]]; then
  echo "usage: scripts/bench-compare.sh NEW.json [BASELINE.json]" >&2
  exit 2
fi
new="${files[0]}"
base="${files[1]:-$here/bench/baselines/linux-x86_64-2core.json}"
case "$metric" in real_time|cpu_time) ;; *) echo "bench-compare: --metric must be real_time or cpu_time" >&2; exit 2 ;; esac

exec python3 - "$new" "$base" "$threshold" "$metric" "$counters" <<'PY'
import json, sys

new_path, base_path, threshold, metric, counters = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4], sys.argv[5] == "1"
UNIT = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}

def load(path):
    try:
        with open(path) as f:
            doc = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        sys.exit(f"bench-compare: {path}: {e}")
    if not isinstance(doc, dict) or not isinstance(doc.get("benchmarks"), list):
        sys.exit(f"bench-compare: {path}: not google-benchmark JSON (no \"benchmarks\" list)")
    rows = {}
    for b in doc["benchmarks"]:
        # Aggregates of --benchmark_repetitions: keep the median only.
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        if "error_occurred" in b or metric not in b:
            continue
        name = b.get("run_name", b["name"])
        rows[name] = b
    return doc, rows

def ns(b):
    return b[metric] * UNIT.get(b.get("time_unit", "ns"), 1.0)

def fmt(v):
    for unit, scale in (("s", 1e9), ("ms", 1e6), ("us", 1e3)):
        if v >= scale:
            return f"{v / scale:.3g} {unit}"
    return f"{v:.3g} ns"

new_doc, new = load(new_path)
base_doc, base = load(base_path)
print(f"new:      {new_path} ({new_doc.get('context', {}).get('date', '?')})")
print(f"baseline: {base_path} ({base_doc.get('context', {}).get('date', '?')})")
load_avg = new_doc.get("context", {}).get("load_avg")
if load_avg:
    print(f"load average of the new run: {', '.join(f'{x:.1f}' for x in load_avg)}")
print(f"metric: {metric}; '!' = slower than x{threshold}\n")
width = max([len(n) for n in new] + [9])
print(f"{'benchmark':<{width}}  {'baseline':>10}  {'new':>10}  {'ratio':>6}")
slower = faster = 0
ratios = []
for name, b in new.items():
    if name not in base:
        print(f"{name:<{width}}  {'-':>10}  {fmt(ns(b)):>10}  {'new':>6}")
        continue
    r = ns(b) / ns(base[name]) if ns(base[name]) > 0 else float("inf")
    ratios.append(r)
    mark = " !" if r > threshold else ""
    slower += r > threshold
    faster += r < 1 / threshold
    print(f"{name:<{width}}  {fmt(ns(base[name])):>10}  {fmt(ns(b)):>10}  {r:6.2f}{mark}")
    if counters:
        for c in ("p50_us", "p99_us", "cands_per_s", "cands", "allocs"):
            if c in b and c in base[name] and base[name][c]:
                print(f"{'  ' + c:<{width}}  {base[name][c]:>10.4g}  {b[c]:>10.4g}  {b[c] / base[name][c]:6.2f}")
for name in base:
    if name not in new:
        print(f"{name:<{width}}  {fmt(ns(base[name])):>10}  {'-':>10}  {'gone':>6}")
if ratios:
    import math
    geo = math.exp(sum(math.log(r) for r in ratios if r > 0) / len(ratios))
    print(f"\n{len(ratios)} compared: geometric mean ratio {geo:.3f}, {slower} slower than x{threshold}, {faster} faster")
PY
