#!/usr/bin/env python3
"""Compare two drives against the oracle, episode by episode and window by window.

    scripts/oracle-compare.py BASE.json NEW.json [--top N] [--json]

BASE and NEW are `frenetic drive ... --oracle --json` reports of the same episodes (the same
scenario, seeds, episode count and latency; a planner or config changed between them). Mean
speeds move +-0.2 mph with chaos, so this pairs what can be paired:

- per episode, the ego's mph along the road (the oracle's measure): the mean difference, its
  standard error, and how many episodes got faster or slower;
- the share of the oracle's lead that NEW closed: (NEW - BASE) / (oracle - BASE), with BASE's
  oracle figure;
- per 20 s window (each starts from the ego's own state, so windows of the same episode, start
  time and length pair up; a lap's last, shorter window only when both drives ended it alike):
  the windows where NEW drove farthest past BASE and farthest behind it,
  with the oracle's lanes and both egos' lanes;
- how the drives differ (when the reports have their breakdown): the speed at the limit and the
  time there, the time following, lane changes and incidents.

--json prints the same as one JSON object. Exit status 2 on unreadable or mismatched reports,
with a one-line message. `--self-test` checks the arithmetic on made-up reports.
"""
import argparse
import json
import math
import sys


class Mismatch(Exception):
    pass


def load(path):
    try:
        with open(path, encoding="utf-8") as f:
            report = json.load(f)
    except (OSError, ValueError) as e:
        raise Mismatch(f"{path}: not a readable JSON report ({e})") from None
    if not isinstance(report, dict) or "oracle" not in report:
        raise Mismatch(f"{path}: no 'oracle' in it; run `frenetic drive ... --oracle --json`")
    episodes = report.get("per_episode")
    if episodes is None:  # one episode: the report is the episode
        episodes = [report]
    if not isinstance(episodes, list) or not episodes:
        raise Mismatch(f"{path}: no episodes in it")
    for k, e in enumerate(episodes):
        o = e.get("oracle") if isinstance(e, dict) else None
        whole = isinstance(o, dict) and all(k in o for k in ("driven_mph", "mph", "windows"))
        fields = ("t", "driven_m", "best_m")
        if not whole or not all(isinstance(w, dict) and all(k in w for k in fields)
                                for w in o["windows"]):
            raise Mismatch(f"{path}: episode {k + 1} has no oracle figures and windows")
    return report, episodes


# The drive's figures from a report's breakdown (the whole run's), or None without one.
DRIVE_FIELDS = ("at_limit_mph", "at_limit_s", "following_s", "lane_changes")


def drive_figures(report):
    b = report.get("breakdown")
    if not isinstance(b, dict) or not all(isinstance(b.get(k), (int, float)) for k in DRIVE_FIELDS):
        return None
    figures = {k: b[k] for k in DRIVE_FIELDS}
    incidents = report.get("incidents")
    figures["incidents"] = incidents if isinstance(incidents, int) else None
    return figures


def describe(e):
    # What makes two episodes the same drive: the scenario and seed (when the report has them).
    return (e.get("scenario"), e.get("seed"))


def compare(base_path, new_path, top):
    base, eb = load(base_path)
    new, en = load(new_path)
    if len(eb) != len(en):
        raise Mismatch(f"{base_path} has {len(eb)} episodes, {new_path} {len(en)}: "
                       "not the same drives")
    for k, (b, n) in enumerate(zip(eb, en)):
        if describe(b) != describe(n):
            raise Mismatch(f"episode {k + 1} is {describe(b)} in {base_path} but {describe(n)} in "
                           f"{new_path}: not the same drives")
    diffs = [n["oracle"]["driven_mph"] - b["oracle"]["driven_mph"] for b, n in zip(eb, en)]
    count = len(diffs)
    mean = sum(diffs) / count if count else 0.0
    se = math.sqrt(sum((d - mean) ** 2 for d in diffs) / (count - 1) / count) if count > 1 else None
    ego_base = sum(e["oracle"]["driven_mph"] for e in eb) / count if count else 0.0
    ego_new = sum(e["oracle"]["driven_mph"] for e in en) / count if count else 0.0
    oracle_base = sum(e["oracle"]["mph"] for e in eb) / count if count else 0.0
    lead = oracle_base - ego_base
    windows = []
    for k, (b, n) in enumerate(zip(eb, en)):
        by_t = {w["t"]: w for w in n["oracle"]["windows"]}
        for wb in b["oracle"]["windows"]:
            wn = by_t.get(wb["t"])
            # A lap's last window ends with the drive: of another length when one ego was faster.
            if wn is None or len(wn.get("driven_lanes", "")) != len(wb.get("driven_lanes", "")):
                continue
            windows.append({
                "episode": k + 1,
                "t": wb["t"],
                "gain_m": wn["driven_m"] - wb["driven_m"],
                "base_m": wb["driven_m"],
                "new_m": wn["driven_m"],
                "oracle_m": wb["best_m"],
                "oracle_lanes": wb.get("lanes", ""),
                "base_lanes": wb.get("driven_lanes", ""),
                "new_lanes": wn.get("driven_lanes", ""),
            })
    windows.sort(key=lambda w: (-w["gain_m"], w["episode"], w["t"]))
    drive_base, drive_new = drive_figures(base), drive_figures(new)
    return {
        "episodes": count,
        "ego_mph": {"base": ego_base, "new": ego_new},
        "oracle_mph": oracle_base,
        "difference_mph": mean,
        "standard_error_mph": se,
        "faster": sum(d > 1e-9 for d in diffs),
        "slower": sum(d < -1e-9 for d in diffs),
        "lead_closed": (ego_new - ego_base) / lead if lead > 0 else None,
        "drive": {"base": drive_base, "new": drive_new} if drive_base and drive_new else None,
        "windows_paired": len(windows),
        "windows_changed": sum(abs(w["gain_m"]) > 1e-6 for w in windows),
        "best_windows": [w for w in windows[:top] if w["gain_m"] > 1e-6],
        "worst_windows": [w for w in reversed(windows[len(windows) - top:]) if w["gain_m"] < -1e-6]
                         if top > 0 else [],
    }


def text(r):
    lines = [
        f"episodes {r['episodes']}: ego {r['ego_mph']['base']:.3f} -> "
        f"{r['ego_mph']['new']:.3f} mph along the road (oracle {r['oracle_mph']:.3f})",
        f"paired difference {r['difference_mph']:+.3f}"
        + (f" +- {r['standard_error_mph']:.3f} mph (one standard error)"
           if r["standard_error_mph"] is not None else " mph (one episode: no standard error)")
        + f"; faster in {r['faster']}, slower in {r['slower']}",
    ]
    if r["lead_closed"] is not None:
        lines.append(f"share of the oracle's lead closed: {100 * r['lead_closed']:.1f}%")
    if r["drive"] is not None:
        b, n = r["drive"]["base"], r["drive"]["new"]
        line = (f"at the limit {b['at_limit_mph']:.2f} -> {n['at_limit_mph']:.2f} mph "
                f"({b['at_limit_s']:,.0f} -> {n['at_limit_s']:,.0f} s), following "
                f"{b['following_s']:,.0f} -> {n['following_s']:,.0f} s, lane changes "
                f"{b['lane_changes']:,} -> {n['lane_changes']:,}")
        if b["incidents"] is not None and n["incidents"] is not None:
            line += f", incidents {b['incidents']} -> {n['incidents']}"
        lines.append(line)
    lines.append(f"windows paired {r['windows_paired']}, changed {r['windows_changed']}")
    for title, key in (("farthest past the base", "best_windows"),
                       ("farthest behind the base", "worst_windows")):
        if r[key]:
            lines.append(f"{title}:")
        for w in r[key]:
            lines.append(f"  episode {w['episode']} from t {w['t']:.1f} s: {w['gain_m']:+.1f} m "
                         f"(base {w['base_m']:.0f}, new {w['new_m']:.0f}, "
                         f"oracle {w['oracle_m']:.0f})")
            lines.append(f"    oracle {w['oracle_lanes']}")
            lines.append(f"    base   {w['base_lanes']}")
            lines.append(f"    new    {w['new_lanes']}")
    return "\n".join(lines)


def self_test():
    import os
    import tempfile

    def report(driven, oracle, windows):
        eps = []
        for d, o, w in zip(driven, oracle, windows):
            eps.append({"oracle": {"driven_mph": d, "mph": o, "windows": [
                {"t": t, "driven_m": m, "best_m": m + 10, "lanes": "1",
                 "driven_lanes": "1" * (40 if t < 40 else int(m))}
                for t, m in w]}})
        return {"oracle": {}, "per_episode": eps, "incidents": 0,
                "breakdown": {"at_limit_mph": 49.3, "at_limit_s": 1000.0, "following_s": 100.0,
                              "lane_changes": 12}}

    def write(path, obj):
        with open(path, "w", encoding="utf-8") as f:
            f.write(obj if isinstance(obj, str) else json.dumps(obj))

    def refused(base_path, new_path, needle, what):
        try:
            compare(base_path, new_path, 5)
        except Mismatch as e:
            assert needle in str(e), e
            return
        raise AssertionError(what)

    # Episode 1's last windows (from t = 40 s) differ in length: not paired.
    base = report([40.0, 42.0], [44.0, 46.0],
                  [[(0.0, 100), (20.0, 100), (40.0, 5)], [(0.0, 200)]])
    new = report([41.0, 44.0], [44.0, 46.0],
                 [[(0.0, 130), (20.0, 90), (40.0, 9)], [(0.0, 200)]])
    new["breakdown"] = {"at_limit_mph": 49.5, "at_limit_s": 990.0, "following_s": 120.0,
                        "lane_changes": 15}
    new["incidents"] = 1
    with tempfile.TemporaryDirectory() as d:
        pb, pn, bad, single = (os.path.join(d, x)
                               for x in ("b.json", "n.json", "bad.json", "one.json"))
        write(pb, base)
        write(pn, new)
        write(bad, "{ not json")
        r = compare(pb, pn, 5)
        assert r["episodes"] == 2
        assert abs(r["difference_mph"] - 1.5) < 1e-12, r
        assert abs(r["standard_error_mph"] - 0.5) < 1e-12, r  # sd 0.707 / sqrt(2)
        assert r["faster"] == 2 and r["slower"] == 0
        # ego 41 -> 42.5, oracle 45: 1.5 of 4 closed.
        assert abs(r["lead_closed"] - 0.375) < 1e-12, r
        assert r["windows_paired"] == 3 and r["windows_changed"] == 2
        assert [w["gain_m"] for w in r["best_windows"]] == [30]
        assert [w["gain_m"] for w in r["worst_windows"]] == [-10]
        assert "+1.500 +- 0.500" in text(r)
        assert r["drive"]["base"]["lane_changes"] == 12, r
        assert ("at the limit 49.30 -> 49.50 mph (1,000 -> 990 s), following 100 -> 120 s, "
                "lane changes 12 -> 15, incidents 0 -> 1") in text(r), text(r)
        refused(pb, bad, "bad.json", "a broken report was read")
        refused(bad, pn, "bad.json", "a broken report was read")
        # A report without its breakdown: no drive line, the rest as before.
        del new["breakdown"]
        write(pn, new)
        rb = compare(pb, pn, 5)
        assert rb["drive"] is None and "at the limit" not in text(rb), rb
        assert abs(rb["difference_mph"] - 1.5) < 1e-12, rb
        # --top 0 lists no window.
        r0 = compare(pb, pn, 0)
        assert r0["best_windows"] == [] and r0["worst_windows"] == [], r0
        # One episode against itself: no standard error.
        one = report([40.0], [44.0], [[(0.0, 100)]])
        write(single, one)
        r1 = compare(single, single, 5)
        assert r1["standard_error_mph"] is None and "no standard error" in text(r1), r1
        refused(pb, single, "2 episodes", "reports of different drives were paired")
        # Other seeds are other drives; a window without its figures is a broken report.
        other = report([40.0, 42.0], [44.0, 46.0], [[(0.0, 100)], [(0.0, 200)]])
        other["per_episode"][1]["seed"] = 7
        base["per_episode"][1]["seed"] = 2
        write(pb, base)
        write(pn, other)
        refused(pb, pn, "episode 2", "episodes of other seeds were paired")
        del other["per_episode"][0]["oracle"]["windows"][0]["t"]
        write(pn, other)
        refused(single, pn, "n.json", "a window without its start was read")
    print("oracle-compare self-test passed")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("base", nargs="?", help="the `drive --oracle --json` report to compare against")
    p.add_argument("new", nargs="?", help="the report of the changed planner, same episodes")
    p.add_argument("--top", type=int, default=5,
                   help="windows listed each way (default: 5; 0: none)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--self-test", action="store_true", help="check the arithmetic and exit")
    a = p.parse_args()
    if a.self_test:
        self_test()
        return 0
    if a.base is None or a.new is None:
        p.error("BASE and NEW reports are needed")
    try:
        r = compare(a.base, a.new, max(0, a.top))
    except Mismatch as e:
        print(f"oracle-compare: {e}", file=sys.stderr)
        return 2
    print(json.dumps(r, indent=1) if a.json else text(r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
