#!/usr/bin/env python3
"""Run the planner on every CommonRoad set this project is checked on, with both predictions.

    scripts/commonroad-sets.py [--shared DIR] [--out DIR] [--frenetic BIN] [--jobs N]
                               [--sets hd,us,deu,zip,ramp,shared] [--predictions recorded,cv]
                               [--baseline DIR] [--json] [-- FRENETIC_OPTION ...]

The sets (docs/commonroad.md tells what each probes), written under OUT/sets on the first run
from the shared files, the same files every time:

  shared  the shared real files: DIR, DIR/us101, DIR/zip and DIR/highD (not written)
  hd      derived from the 30 highD recordings: every vehicle with 4 and 7 s of recording after
          its start, its lane at the horizon as the goal (commonroad-derive.py --goal lane)
  us      derived from USA_US101-10_1_T-1, horizons 8, 5 and 6 s (commonroad-derive.py)
  deu     derived from the German scenes and ZAM_Ramp-1_1, horizons 8, 5 and 3 s
  zip     zipper merges with new traffic on ZAM_Zip-1_1's road, seeds 1-200 (commonroad-zips.py)
  ramp    hand-made motorway entries and exits (commonroad-ramps.py)

Each set is run with `frenetic commonroad ... --no-timing --json --prediction P` (byte-stable:
the same build gives the same files) into OUT/results/SET-P.json, and a table of problems solved
of those feasible at start is printed per set and prediction. A derived problem's solution
exists (a recorded vehicle drove it), so an unsolved one is the planner's miss, unless it is
infeasible at start. The derived sets share roads and recordings with the shared files: they
check a change for regressions, they are not held-out figures.

--baseline DIR: another run's OUT (e.g. of the build before a change); its counts are printed
beside, and the problems whose outcome (solved or not) differs are listed. Options after `--` go
to every `frenetic commonroad` run, so that a configuration is compared with the default on every
set by the same build (the sets are written once and shared):

    scripts/commonroad-sets.py --out build/cr-main
    scripts/commonroad-sets.py --out build/cr-try --baseline build/cr-main \
        -- --commonroad-config try.yaml          # or --rescue-retry 1000, --vehicle 3, ...

The options are passed as they are: one that `frenetic commonroad` refuses fails the first run
with its message. Options the script sets itself (--json, --no-timing, --prediction, --jobs) are
refused here. --json prints one
JSON object instead. Exit status 0 when every run completed (unsolved problems are results), 2
on a missing input, a failed generator or a run that printed no report, with a one-line message.
`--self-test` checks the counting and comparing on made-up reports.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

from scenario_files import scenario_files

SETS = ("shared", "hd", "us", "deu", "zip", "ramp")
# Options the script gives every run itself; not accepted after `--`.
OWN_OPTIONS = ("--json", "--no-timing", "--prediction", "--jobs")
PREDICTIONS = {"recorded": "recorded", "cv": "constant-velocity",
               "constant-velocity": "constant-velocity"}
HERE = os.path.dirname(os.path.abspath(__file__))


class Failure(Exception):
    pass


def generators(shared, out):
    """The commands that write each derived set into out/SET: {set: [argv, ...]}."""
    def derive(path, name, horizon, *extra):
        return [sys.executable, os.path.join(HERE, "commonroad-derive.py"), path,
                os.path.join(out, name), "--horizon", str(horizon), *extra]

    def files(folder, prefixes=("",)):
        if not os.path.isdir(folder):
            raise Failure(f"{folder}: no such directory (--shared names the shared CommonRoad files)")
        return [f for f in scenario_files(folder, skip_solutions=True)
                if os.path.basename(f).startswith(prefixes)]

    us = os.path.join(shared, "USA_US101-10_1_T-1.xml")
    return {
        "hd": [derive(f, "hd", h, "--goal", "lane")
               for f in files(os.path.join(shared, "highD")) for h in (4, 7)],
        "us": [derive(us, "us", h) for h in (8, 5, 6)],
        "deu": [derive(f, "deu", h) for f in files(shared, ("DEU_", "ZAM_"))
                for h in (8, 5, 3)],
        "zip": [[sys.executable, os.path.join(HERE, "commonroad-zips.py"),
                 os.path.join(shared, "zip", "ZAM_Zip-1_1_T-1.xml"), os.path.join(out, "zip"),
                 "--seeds", "1-200"]],
        "ramp": [[sys.executable, os.path.join(HERE, "commonroad-ramps.py"),
                  os.path.join(out, "ramp")]],
    }


def write_set(name, shared, out):
    """out/NAME, written by the set's generators (into out/.partial/NAME, moved when complete)
    unless an earlier run wrote it: the same files each time."""
    folder = os.path.join(out, name)
    if os.path.isdir(folder) and any(n.endswith(".xml") for n in os.listdir(folder)):
        return folder
    staging = os.path.join(out, ".partial")
    shutil.rmtree(os.path.join(staging, name), ignore_errors=True)
    for argv in generators(shared, staging)[name]:
        r = subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if r.returncode != 0:
            last = (r.stderr.strip().splitlines() or ["no message"])[-1]
            raise Failure(f"writing set {name}: {os.path.basename(argv[1])} failed: {last}")
    if not os.path.isdir(os.path.join(staging, name)):
        raise Failure(f"writing set {name}: the generators wrote no file")
    os.replace(os.path.join(staging, name), folder)
    try:
        os.rmdir(staging)  # when no other set is being written there
    except OSError:
        pass
    return folder


def counts(report, path):
    """Problems, infeasible at start and solved of a `frenetic commonroad --json` report, and
    each problem's outcome by (benchmark id, problem id)."""
    s = report.get("summary") if isinstance(report, dict) else None
    if not isinstance(s, dict) or not all(isinstance(s.get(k), int)
                                          for k in ("problems", "solved", "infeasible_at_start")):
        raise Failure(f"{path}: not a `frenetic commonroad --json` report (no summary counts)")
    outcome, figures = {}, {}
    for sc in report.get("scenarios", []):
        for p in sc.get("problems", []):
            key = f"{sc.get('benchmark_id')}#{p.get('problem')}"
            outcome[key] = ("infeasible at start" if p.get("stop") == "infeasible_at_start"
                            else "solved" if p.get("solved") else f"unsolved ({p.get('stop')})")
            figures[key] = json.dumps(p, sort_keys=True)
    return {"problems": s["problems"], "infeasible_at_start": s["infeasible_at_start"],
            "solved": s["solved"], "feasible": s["problems"] - s["infeasible_at_start"],
            "outcome": outcome, "figures": figures}


def load(path):
    try:
        with open(path, encoding="utf-8") as f:
            return counts(json.load(f), path)
    except (OSError, ValueError) as e:
        raise Failure(f"{path}: not a readable report ({e})") from None


def changed(base, new):
    """Problems whose outcome differs between two counts of the same set: [(key, base, new)]."""
    keys = sorted(set(base["outcome"]) | set(new["outcome"]))
    return [(k, base["outcome"].get(k, "absent"), new["outcome"].get(k, "absent"))
            for k in keys if base["outcome"].get(k) != new["outcome"].get(k)]


def differ(base, new):
    """How many problems differ in any figure (cost, steps, failures...) between two counts."""
    keys = set(base["figures"]) | set(new["figures"])
    return sum(1 for k in keys if base["figures"].get(k) != new["figures"].get(k))


def table(results, baseline):
    lines = []
    preds = sorted({p for r in results.values() for p in r}, reverse=True)  # recorded first
    head = f"{'set':8} {'problems':>8} {'infeasible':>10}"
    for p in preds:
        head += f"  {p:>19}" + (f" {'(baseline)':>12}" if baseline else "")
    lines.append(head)
    for name, by_pred in results.items():
        any_r = next(iter(by_pred.values()))
        row = f"{name:8} {any_r['problems']:>8} {any_r['infeasible_at_start']:>10}"
        for p in preds:
            r = by_pred.get(p)
            row += f"  {r['solved']:>10} / {r['feasible']:<6}" if r else f"  {'-':>19}"
            if baseline:
                b = baseline.get(name, {}).get(p)
                row += f" {b['solved']:>5} / {b['feasible']:<4}" if b else f" {'-':>12}"
        lines.append(row)
    if baseline:
        for name, by_pred in results.items():
            for p, r in by_pred.items():
                b = baseline.get(name, {}).get(p)
                if b is None:
                    continue
                diff = changed(b, r)
                lines.append(f"{name}, {p}: {len(diff)} changed outcome, {differ(b, r)} differ "
                             "in some figure")
                lines += [f"  {k}: {was} -> {now}" for k, was, now in diff]
    return "\n".join(lines)


def split_args(argv):
    """The script's own arguments, and those after `--` (for frenetic commonroad)."""
    if "--" not in argv:
        return list(argv), []
    i = argv.index("--")
    return list(argv[:i]), list(argv[i + 1:])


def check_frenetic_args(extra):
    for a in extra:
        if a.split("=", 1)[0] in OWN_OPTIONS:
            raise Failure(f"{a} after --: the script sets it itself (its own --jobs and "
                          "--predictions choose those)")


def run(args):
    shared = os.path.abspath(args.shared)
    out = os.path.abspath(args.out)
    sets = [s.strip() for s in args.sets.split(",") if s.strip()]
    for s in sets:
        if s not in SETS:
            raise Failure(f"--sets: unknown set '{s}' (one of {', '.join(SETS)})")
    preds = []
    for p in args.predictions.split(","):
        if p.strip() not in PREDICTIONS:
            raise Failure(f"--predictions: unknown prediction '{p.strip()}' "
                          "(recorded, cv or constant-velocity)")
        preds.append(PREDICTIONS[p.strip()])
    if args.baseline and not os.path.isdir(os.path.join(args.baseline, "results")):
        raise Failure(f"--baseline {args.baseline}: no results/ in it (another run's --out)")
    check_frenetic_args(args.frenetic_args)
    if not os.access(args.frenetic, os.X_OK):
        raise Failure(f"{args.frenetic}: no such executable (build it: scripts/run.sh --help)")
    os.makedirs(os.path.join(out, "sets"), exist_ok=True)
    os.makedirs(os.path.join(out, "results"), exist_ok=True)
    results = {}
    for name in sets:
        if name == "shared":
            inputs = [shared] + [os.path.join(shared, d) for d in ("us101", "zip", "highD")
                                 if os.path.isdir(os.path.join(shared, d))]
        else:
            inputs = [write_set(name, shared, os.path.join(out, "sets"))]
        for p in preds:
            path = os.path.join(out, "results", f"{name}-{p}.json")
            if not args.json:
                print(f"[commonroad-sets] {name}, {p} ...", file=sys.stderr, flush=True)
            with open(path, "w", encoding="utf-8") as f:
                r = subprocess.run([args.frenetic, "commonroad", *inputs, "--no-timing", "--json",
                                    "--prediction", p, "--jobs", str(args.jobs),
                                    *args.frenetic_args],
                                   stdout=f, stderr=subprocess.PIPE, text=True)
            if r.returncode != 0:
                lines = [ln for ln in r.stderr.strip().splitlines()
                         if ln.strip() and not ln.startswith("Run with --help")]
                last = (lines or ["no message"])[-1]
                raise Failure(f"frenetic commonroad on set {name} ({p}) exited {r.returncode}: {last}")
            results.setdefault(name, {})[p] = load(path)
    baseline = None
    if args.baseline:
        baseline = {}
        for name in sets:
            for p in preds:
                path = os.path.join(args.baseline, "results", f"{name}-{p}.json")
                if os.path.exists(path):
                    baseline.setdefault(name, {})[p] = load(path)
    return results, baseline


def as_json(results, baseline):
    def strip(r):
        return {k: v for k, v in r.items() if k not in ("outcome", "figures")}
    obj = {"sets": {n: {p: strip(r) for p, r in bp.items()} for n, bp in results.items()}}
    if baseline is not None:
        obj["baseline"] = {n: {p: strip(r) for p, r in bp.items()} for n, bp in baseline.items()}
        obj["changed"] = {n: {p: [{"problem": k, "baseline": was, "now": now}
                                  for k, was, now in changed(baseline[n][p], r)]
                              for p, r in bp.items() if p in baseline.get(n, {})}
                          for n, bp in results.items() if n in baseline}
        obj["differ"] = {n: {p: differ(baseline[n][p], r)
                             for p, r in bp.items() if p in baseline.get(n, {})}
                         for n, bp in results.items() if n in baseline}
    return obj


def self_test():
    def report(problems):
        scenarios = {}
        for bid, pid, stop, solved in problems:
            scenarios.setdefault(bid, []).append({"problem": pid, "stop": stop, "solved": solved})
        return {"summary": {"problems": len(problems),
                            "solved": sum(1 for p in problems if p[3]),
                            "infeasible_at_start": sum(1 for p in problems
                                                       if p[2] == "infeasible_at_start")},
                "scenarios": [{"benchmark_id": b, "problems": ps} for b, ps in scenarios.items()]}

    base = counts(report([("A", 1, "goal", True), ("B", 2, "collision", False),
                          ("C", 3, "infeasible_at_start", False)]), "base")
    new = counts(report([("A", 1, "collision", False), ("B", 2, "goal", True),
                         ("C", 3, "infeasible_at_start", False)]), "new")
    assert (base["problems"], base["infeasible_at_start"], base["solved"], base["feasible"]) == \
        (3, 1, 1, 2), base
    assert changed(base, base) == []
    assert changed(base, new) == [("A#1", "solved", "unsolved (collision)"),
                                  ("B#2", "unsolved (collision)", "solved")], changed(base, new)
    # A problem only one run has is a change too.
    extra = counts(report([("A", 1, "goal", True), ("B", 2, "collision", False),
                           ("C", 3, "infeasible_at_start", False), ("D", 4, "goal", True)]), "x")
    assert changed(base, extra) == [("D#4", "absent", "solved")]
    t = table({"hd": {"recorded": new}}, {"hd": {"recorded": base}})
    assert "hd, recorded: 2 changed outcome, 2 differ in some figure" in t, t
    assert "A#1: solved -> unsolved (collision)" in t, t
    # The same outcome at another cost: a figure differs, no outcome changed.
    dearer = report([("A", 1, "goal", True), ("B", 2, "collision", False),
                     ("C", 3, "infeasible_at_start", False)])
    dearer["scenarios"][0]["problems"][0]["costs"] = {"WX1": 2.0}
    dearer = counts(dearer, "dearer")
    assert changed(base, dearer) == [] and differ(base, dearer) == 1 and differ(base, base) == 0
    assert "1 / 2" in t, t
    j = as_json({"hd": {"recorded": new}}, {"hd": {"recorded": base}})
    assert j["sets"]["hd"]["recorded"]["solved"] == 1 and len(j["changed"]["hd"]["recorded"]) == 2
    assert j["differ"]["hd"]["recorded"] == 2 and "figures" not in j["sets"]["hd"]["recorded"], j
    for bad in ({}, {"summary": {"problems": 1}}, [1, 2]):
        try:
            counts(bad, "bad.json")
        except Failure as e:
            assert "bad.json" in str(e), e
        else:
            raise AssertionError(f"{bad} was read as a report")
    assert split_args(["--sets", "hd"]) == (["--sets", "hd"], [])
    assert split_args(["--out", "x", "--", "--rescue-retry", "1000", "--", "y"]) == \
        (["--out", "x"], ["--rescue-retry", "1000", "--", "y"])
    check_frenetic_args(["--commonroad-config", "a.yaml", "--vehicle=3"])
    for own in (["--json"], ["--jobs", "2"], ["--prediction=recorded"], ["--no-timing"]):
        try:
            check_frenetic_args(own)
        except Failure as e:
            assert own[0] in str(e), e
        else:
            raise AssertionError(f"{own} was passed on")
    print("commonroad-sets self-test passed")


def main():
    root = os.path.dirname(HERE)
    build = os.environ.get("FRENETIC_BUILD_DIR") or os.path.join(root, "build")  # as common.sh
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--shared", default=os.path.join(root, "..", "shared", "commonroad"),
                   help="the shared CommonRoad files (default: ../shared/commonroad beside the "
                        "repository)")
    p.add_argument("--out", default=os.path.join(build, "commonroad-sets"),
                   help="where the sets and results go (default: build/commonroad-sets, in "
                        "$FRENETIC_BUILD_DIR when set)")
    p.add_argument("--frenetic", default=os.path.join(build, "frenetic"),
                   help="the frenetic executable (default: build/frenetic, in "
                        "$FRENETIC_BUILD_DIR when set)")
    p.add_argument("--jobs", type=int, default=0,
                   help="scenario files planned in parallel (frenetic commonroad --jobs; default "
                        "0: every core this process may use)")
    p.add_argument("--sets", default=",".join(SETS),
                   help=f"comma-separated sets to run (default: all: {','.join(SETS)})")
    p.add_argument("--predictions", default="recorded,cv",
                   help="comma-separated: recorded, cv (constant velocity) (default: both)")
    p.add_argument("--baseline", help="another run's --out to compare with")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--self-test", action="store_true", help="check the counting and exit")
    argv, extra = split_args(sys.argv[1:])  # what follows `--` goes to frenetic commonroad
    a = p.parse_args(argv)
    a.frenetic_args = extra
    if a.self_test:
        self_test()
        return 0
    try:
        results, baseline = run(a)
    except Failure as e:
        print(f"commonroad-sets: {e}", file=sys.stderr)
        return 2
    if a.json:
        obj = as_json(results, baseline)
        obj["frenetic_args"] = a.frenetic_args
        print(json.dumps(obj, indent=1))
    else:
        if a.frenetic_args:
            print("frenetic commonroad options: " + " ".join(a.frenetic_args))
        print(table(results, baseline))
    return 0


if __name__ == "__main__":
    sys.exit(main())
