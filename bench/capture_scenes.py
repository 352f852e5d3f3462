#!/usr/bin/env python3
"""Cuts a small benchmark scene out of a `frenetic drive --record FILE.jsonl` record.

A scene is a header line and COUNT consecutive exchanges, each reduced to what the benchmark
replays (the time and the telemetry the simulator sent) plus a few plan fields for reference.
Where the window starts:
  --at T            first exchange at simulated time >= T seconds
  --lane-change     first exchange (after --at) whose winner lane differs from the ego's lane
                    while the ego is already off its lane centre (a lane change in progress)
  --seam            the window around the first crossing of the loop's wrap (s falls by > L/2)
  --most-checked    the window around the search cycle (after --at, before --until) that checked
                    the most candidates before one passed (ties: the earliest): the cycles that
                    make the per-exchange tail of whole drives
  --slowest         the same around the longest planning time (plan.ms_total); needs a record
                    made without --no-timing, so the window depends on the machine
The worst cycle is the third of the window (with --count 5): the benchmark plans the first
message cold and measures the others.

Example (bench/scenes/README.md has the commands for every committed scene):
  frenetic drive --scenario dense --seed 3 --seconds 40 --no-timing --record /tmp/dense.jsonl
  bench/capture_scenes.py /tmp/dense.jsonl bench/scenes/dense_traffic.jsonl dense_traffic --at 25
"""
import argparse
import gzip
import json
import os
import sys


def fail(msg):
    print(f"capture_scenes: {msg}", file=sys.stderr)
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("record")
    ap.add_argument("out")
    ap.add_argument("name")
    ap.add_argument("--at", type=float, default=0.0)
    ap.add_argument("--lane-change", action="store_true")
    ap.add_argument("--seam", action="store_true")
    ap.add_argument("--most-checked", action="store_true")
    ap.add_argument("--slowest", action="store_true")
    ap.add_argument("--until", type=float, default=float("inf"))
    ap.add_argument("--count", type=int, default=5)
    ap.add_argument("--command", default="", help="the drive command, stored in the header")
    a = ap.parse_args()
    if a.count < 2:
        fail("--count must be >= 2")

    header, exchanges = None, []
    with open(a.record, "rb") as probe:  # `drive --record run.jsonl.gz` writes gzip
        gzipped = probe.read(2) == b"\x1f\x8b"
    with (gzip.open(a.record, "rt") if gzipped else open(a.record)) as f:
        for n, line in enumerate(f, 1):
            try:
                j = json.loads(line)
            except json.JSONDecodeError as e:
                fail(f"{a.record}:{n}: not JSON ({e})")
            if j.get("type") == "header":
                header = j
            elif j.get("type") == "exchange" and isinstance(j.get("telemetry"), dict):
                exchanges.append(j)
    if header is None:
        fail(f"{a.record}: no header line")

    if a.most_checked and a.slowest:
        fail("--most-checked and --slowest exclude each other")
    start = None
    if a.most_checked or a.slowest:
        key = "candidates_checked" if a.most_checked else "ms_total"
        best, best_i = None, None
        for i, e in enumerate(exchanges):
            p = e.get("plan") or {}
            if not (a.at <= e["t"] < a.until) or not p.get("candidates_generated"):
                continue
            if best is None or p.get(key, 0) > best:
                best, best_i = p.get(key, 0), i
        if best_i is None:
            fail(f"{a.record}: no search cycle between t = {a.at} and {a.until}")
        if a.slowest and not best:
            fail(f"{a.record}: no planning times (recorded with --no-timing?)")
        print(f"worst cycle: #{exchanges[best_i]['i']} (t = {exchanges[best_i]['t']:.2f} s), "
              f"{key} = {best}")
        start = min(max(0, best_i - a.count // 2), len(exchanges) - a.count)
    elif a.seam:
        for i in range(1, len(exchanges)):
            if exchanges[i]["telemetry"]["s"] < exchanges[i - 1]["telemetry"]["s"] - 1000:
                start = max(0, i - a.count // 2)
                break
    else:
        width = header.get("lane_width", 4)
        for i, e in enumerate(exchanges):
            if e["t"] < a.at:
                continue
            if a.lane_change:
                d = e["telemetry"]["d"]
                lane = int(d // width)
                off_centre = abs(d - (lane + 0.5) * width) > 0.8
                if not (off_centre and e["plan"]["winner_lane"] not in (-1, lane)):
                    continue
            start = i
            break
    if start is None or start + a.count > len(exchanges):
        fail(f"{a.record}: no window of {a.count} exchanges matches")

    root = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
    map_path = header["map"]
    if os.path.isabs(map_path) and map_path.startswith(root + os.sep):
        map_path = os.path.relpath(map_path, root)
    keep = ("status", "candidates_generated", "candidates_checked", "winner_lane",
            "winner_end_speed", "winner_total_cost")
    with open(a.out, "w") as out:
        out.write(json.dumps({
            "type": "header", "scene": a.name, "map": map_path,
            "scenario": header.get("scenario"), "seed": header.get("seed"),
            "planner": header.get("planner"), "first_exchange": exchanges[start]["i"],
            "command": a.command}, separators=(",", ":")) + "\n")
        for e in exchanges[start:start + a.count]:
            line = {"type": "exchange", "i": e["i"], "t": e["t"], "telemetry": e["telemetry"],
                    "plan": {k: e["plan"][k] for k in keep if k in e["plan"]},
                    "lane": e["metrics"]["lane"]}
            out.write(json.dumps(line, separators=(",", ":")) + "\n")
    print(f"{a.out}: {a.count} exchanges from #{exchanges[start]['i']} "
          f"(t = {exchanges[start]['t']:.2f} s), {os.path.getsize(a.out)} bytes")


if __name__ == "__main__":
    main()
