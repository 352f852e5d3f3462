#!/usr/bin/env python3
"""Derives more CommonRoad planning problems from a recorded scenario, the way CommonRoad made its
NGSIM ones: one of the recorded vehicles is taken out of the traffic and becomes the ego, its
initial state the problem's, and the goal is where that vehicle was at the end of a time window
(a rectangle along its heading, its lane's width, velocity and orientation intervals around its
recorded ones, like the goals of USA_US101-10_1_T-1). The recorded vehicle reached it, so a
solution exists, unless the recorded vehicle starts off the lanelets (its box over a road edge at
the initial state, which CommonRoad's road rule fails whatever follows): such vehicles are not
taken. Writes one file per vehicle whose recording is long enough.

    scripts/commonroad-derive.py SCENARIO.xml OUT_DIR [--horizon 8] [--goal-length 4]

The derived files are test inputs made from the shared data at run time: not part of the tree.
"""
import argparse
import copy
import math
import os
import sys
import xml.etree.ElementTree as ET


def states(obstacle):
    out = [obstacle.find("initialState")]
    out += obstacle.findall("trajectory/state")
    return out


def value(state, name):
    node = state.find(f"{name}/exact")
    return float(node.text) if node is not None else None


def position(state):
    p = state.find("position/point")
    return float(p.find("x").text), float(p.find("y").text)


def interval(parent, name, lo, hi, integer=False):
    node = ET.SubElement(parent, name)
    fmt = (lambda v: str(int(v))) if integer else (lambda v: f"{v:.4f}")
    ET.SubElement(node, "intervalStart").text = fmt(lo)
    ET.SubElement(node, "intervalEnd").text = fmt(hi)


def extend(a, b, margin=5.0):
    dx, dy = b[0] - a[0], b[1] - a[1]
    n = math.hypot(dx, dy) or 1.0
    return (b[0] + margin * dx / n, b[1] + margin * dy / n)


def lanelet_polygons(root):
    out = []
    for ll in root.findall("lanelet"):
        left = [(float(p.find("x").text), float(p.find("y").text)) for p in ll.findall("leftBound/point")]
        right = [(float(p.find("x").text), float(p.find("y").text)) for p in ll.findall("rightBound/point")]
        # Open ends go on 5 m (RoadArea::kDefaultOpenEndMargin), as the verdict's road does.
        if ll.find("successor") is None:
            left, right = left + [extend(left[-2], left[-1])], right + [extend(right[-2], right[-1])]
        if ll.find("predecessor") is None:
            left, right = [extend(left[1], left[0])] + left, [extend(right[1], right[0])] + right
        out.append(left + right[::-1])
    return out


def inside(poly, x, y):
    # Even-odd rule, with a few centimetres of tolerance left to the verdict's own.
    hit = False
    n = len(poly)
    for i in range(n):
        (x1, y1), (x2, y2) = poly[i], poly[(i + 1) % n]
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            hit = not hit
    return hit


def on_lanelets(polys, state, length, width):
    x, y = position(state)
    h = value(state, "orientation") or 0.0
    c, s = math.cos(h), math.sin(h)
    for a, b in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
        px = x + a * 0.5 * length * c - b * 0.5 * width * s
        py = y + a * 0.5 * length * s + b * 0.5 * width * c
        if not any(inside(p, px, py) for p in polys):
            return False
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario")
    ap.add_argument("out_dir")
    ap.add_argument("--horizon", type=float, default=8.0, help="s from the start to the goal's window end")
    ap.add_argument("--window", type=float, default=1.0, help="s, the goal's time window length")
    ap.add_argument("--goal-length", type=float, default=4.0, help="m, the goal rectangle's length")
    ap.add_argument("--min-speed", type=float, default=2.0, help="m/s: slower vehicles are not taken")
    args = ap.parse_args()

    tree = ET.parse(args.scenario)
    root = tree.getroot()
    dt = float(root.get("timeStepSize", "0.1"))
    steps = int(round(args.horizon / dt))
    window = int(round(args.window / dt))
    base_id = root.get("benchmarkID")
    os.makedirs(args.out_dir, exist_ok=True)
    polys = lanelet_polygons(root)
    made = 0
    for obstacle in root.findall("dynamicObstacle"):
        st = states(obstacle)
        t0 = int(st[0].find("time/exact").text)
        if t0 != 0 or len(st) <= steps:
            continue
        v0 = value(st[0], "velocity")
        if v0 is None or v0 < args.min_speed:
            continue
        length = float(obstacle.find("shape/rectangle/length").text)
        w = float(obstacle.find("shape/rectangle/width").text)
        if not on_lanelets(polys, st[0], length - 0.1, w - 0.1):
            print(f"vehicle {obstacle.get('id')}: starts off the lanelets; not taken", file=sys.stderr)
            continue
        goal = st[steps]
        gx, gy = position(goal)
        heading = value(goal, "orientation") or 0.0
        v_goal = value(goal, "velocity")
        if v_goal is None:  # (a recorded 0.0 is a speed: the vehicle stopped there)
            v_goal = v0
        width = float(obstacle.find("shape/rectangle/width").text) + 1.5

        new_root = copy.deepcopy(root)
        for o in new_root.findall("dynamicObstacle"):
            if o.get("id") == obstacle.get("id"):
                new_root.remove(o)
        for p in new_root.findall("planningProblem"):
            new_root.remove(p)
        problem = ET.SubElement(new_root, "planningProblem", id=str(100000 + int(obstacle.get("id"))))
        init = ET.SubElement(problem, "initialState")
        x, y = position(st[0])
        pos = ET.SubElement(ET.SubElement(init, "position"), "point")
        ET.SubElement(pos, "x").text = f"{x:.4f}"
        ET.SubElement(pos, "y").text = f"{y:.4f}"
        for name, val in (("orientation", value(st[0], "orientation") or 0.0), ("time", 0),
                          ("velocity", v0), ("yawRate", 0.0), ("slipAngle", 0.0)):
            ET.SubElement(ET.SubElement(init, name), "exact").text = str(val)
        gs = ET.SubElement(problem, "goalState")
        rect = ET.SubElement(ET.SubElement(gs, "position"), "rectangle")
        ET.SubElement(rect, "length").text = f"{args.goal_length:.4f}"
        ET.SubElement(rect, "width").text = f"{width:.4f}"
        ET.SubElement(rect, "orientation").text = f"{heading:.5f}"
        c = ET.SubElement(rect, "center")
        ET.SubElement(c, "x").text = f"{gx:.4f}"
        ET.SubElement(c, "y").text = f"{gy:.4f}"
        interval(gs, "orientation", heading - 0.0873, heading + 0.0873)
        interval(gs, "time", steps - window, steps, integer=True)
        interval(gs, "velocity", max(0.0, v_goal - 3.0), v_goal + 3.0)
        name = f"{base_id}_ego{obstacle.get('id')}"
        if args.horizon != 8.0:  # several horizons side by side
            name += f"_h{args.horizon:g}"
        new_root.set("benchmarkID", name)
        ET.ElementTree(new_root).write(os.path.join(args.out_dir, name + ".xml"),
                                       encoding="unicode", xml_declaration=True)
        made += 1
    print(f"{args.scenario}: {made} problems in {args.out_dir}", file=sys.stderr)


if __name__ == "__main__":
    main()
