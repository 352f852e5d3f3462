#!/usr/bin/env python3
"""Writes a CommonRoad scenario at another time step size DT (s): every trajectory obstacle's
states at the steps of DT (linear between the recorded ones, the heading the short way round,
speed and acceleration likewise), the goals' time windows in those steps (the whole steps within
them), the problems' initial steps likewise, `timeStepSize` set to DT. The traffic moves as it
did, in seconds. CommonRoad's own converters write a recording's rate (highD, exiD: 25 Hz,
0.04 s) unless told to downsample, so a planner that works only at 0.1 s fails such files; run
a set both ways and compare (docs/commonroad.md, "A file's own step size").

    scripts/commonroad-resample.py IN.xml|IN_DIR OUT_DIR --dt 0.05

Files with set-based predictions (<occupancySet>) and solution files are skipped. The written
files are test inputs made from the shared data at run time: not part of the tree.
"""
import argparse
import copy
import math
import sys
import xml.etree.ElementTree as ET

from scenario_files import rewrite_each, scenario_files


def number(node, path):
    n = node.find(path)
    return float(n.text) if n is not None else None


def step_of(state):
    return int(round(float(state.find("time/exact").text)))


def between(a, b, w, step):
    """State a moved w of the way to state b, at `step`."""
    s = copy.deepcopy(a)
    s.tag = "state"
    s.find("time/exact").text = str(step)
    for path in ("position/point/x", "position/point/y", "velocity/exact", "acceleration/exact"):
        va, vb = number(a, path), number(b, path)
        if va is not None and vb is not None:
            s.find(path).text = repr(round(va + w * (vb - va), 6))
    oa, ob = number(a, "orientation/exact"), number(b, "orientation/exact")
    if oa is not None and ob is not None:
        turn = math.atan2(math.sin(ob - oa), math.cos(ob - oa))
        s.find("orientation/exact").text = repr(round(oa + w * turn, 6))
    return s


def resample(src, dst, dt):
    """False when the file is skipped (set-based predictions)."""
    tree = ET.parse(src)
    root = tree.getroot()
    r = dt / float(root.get("timeStepSize"))
    root.set("timeStepSize", repr(dt))
    for obstacle in root.findall("dynamicObstacle"):
        if obstacle.find("occupancySet") is not None:
            return False
        initial, trajectory = obstacle.find("initialState"), obstacle.find("trajectory")
        states = [initial] + (trajectory.findall("state") if trajectory is not None else [])
        by_step = {step_of(s): s for s in states}
        a0, a1 = min(by_step), max(by_step)
        new = []
        for j in range(math.ceil(a0 / r - 1e-9), math.floor(a1 / r + 1e-9) + 1):
            u = j * r
            k = min(int(math.floor(u + 1e-9)), a1)
            w = u - k if k < a1 else 0.0
            new.append(between(by_step[k], by_step[min(k + 1, a1)], w, j))
        if not new:
            root.remove(obstacle)
            continue
        new[0].tag = "initialState"
        at = list(obstacle).index(initial)
        obstacle.remove(initial)
        obstacle.insert(at, new[0])
        if trajectory is not None:
            for s in list(trajectory):
                trajectory.remove(s)
            for s in new[1:]:
                trajectory.append(s)
            if len(new) == 1:
                obstacle.remove(trajectory)
    for problem in root.findall("planningProblem"):
        exact = problem.find("initialState/time/exact")
        if exact is not None:
            exact.text = str(int(round(int(exact.text) / r)))
    for goal in root.iter("goalState"):
        time = goal.find("time")
        if time is None:
            continue
        lo, hi = time.find("intervalStart"), time.find("intervalEnd")
        if lo is not None and hi is not None:
            a, b = int(lo.text), int(hi.text)
            na, nb = math.ceil(a / r - 1e-9), math.floor(b / r + 1e-9)
            if nb < na:
                na = nb = int(round(a / r))
            lo.text, hi.text = str(na), str(nb)
        exact = time.find("exact")
        if exact is not None:
            exact.text = str(int(round(int(exact.text) / r)))
    tree.write(dst, encoding="utf-8", xml_declaration=True)
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("source", help="a scenario file or a directory of them")
    ap.add_argument("out_dir")
    ap.add_argument("--dt", type=float, required=True, help="s, the new time step size")
    a = ap.parse_args()
    if not a.dt > 0:
        print("--dt must be positive", file=sys.stderr)
        return 1
    return rewrite_each(scenario_files(a.source, skip_solutions=True), a.out_dir,
                        lambda src, dst: resample(src, dst, a.dt))


if __name__ == "__main__":
    sys.exit(main())
