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

`--goal lane` makes goals like those of the highD problems instead (CommonRoad's traffic-rule set):
the whole width of the lane the vehicle was in at the horizon, 6.6 m long across its lane's
heading, the heading +-0.2 rad, the speed +-10 m/s, a time window from step 0 to --window-end.

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


def lane_at(root, x, y):
    """The lane under (x, y): its centre, width and heading across the nearest section of the
    lanelet whose outline holds the point (None when no lanelet does)."""
    for ll in root.findall("lanelet"):
        left = [(float(p.find("x").text), float(p.find("y").text)) for p in ll.findall("leftBound/point")]
        right = [(float(p.find("x").text), float(p.find("y").text)) for p in ll.findall("rightBound/point")]
        if not inside(left + right[::-1], x, y):
            continue
        best = None
        for bound in (left, right):
            for i in range(len(bound) - 1):
                (x1, y1), (x2, y2) = bound[i], bound[i + 1]
                dx, dy = x2 - x1, y2 - y1
                n2 = dx * dx + dy * dy
                if n2 == 0.0:
                    continue
                t = max(0.0, min(1.0, ((x - x1) * dx + (y - y1) * dy) / n2))
                px, py = x1 + t * dx, y1 + t * dy
                d = math.hypot(x - px, y - py)
                if best is None or d < best[0]:
                    best = (d, math.atan2(dy, dx))
        heading = best[1]
        nx, ny = -math.sin(heading), math.cos(heading)

        def across(bound):  # the bound's point nearest (x, y)
            return min(bound, key=lambda q: math.hypot(q[0] - x, q[1] - y))
        lo, hi = (across(left), across(right))
        o_left = (lo[0] - x) * nx + (lo[1] - y) * ny
        o_right = (hi[0] - x) * nx + (hi[1] - y) * ny
        mid = 0.5 * (o_left + o_right)
        return (x + mid * nx, y + mid * ny), abs(o_left - o_right), heading
    return None


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
    ap.add_argument("--goal", choices=("rect", "lane"), default="rect",
                    help="rect: a rectangle around the vehicle at the horizon, a 1 s window; "
                         "lane: its lane's width, 6.6 m, speed +-10 m/s, steps 0 to --window-end")
    ap.add_argument("--window-end", type=int, default=1000, help="steps, the lane goal's window end")
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
        goal_length, heading_tol, v_tol = args.goal_length, 0.0873, 3.0
        time_window = (steps - window, steps)
        if args.goal == "lane":
            lane = lane_at(root, gx, gy)
            if lane is None:
                print(f"vehicle {obstacle.get('id')}: ends off the lanelets; not taken", file=sys.stderr)
                continue
            (gx, gy), width, lane_heading = lane
            if abs(math.remainder(lane_heading - heading, 2 * math.pi)) < 0.5 * math.pi:
                heading = lane_heading
            goal_length, heading_tol, v_tol = 6.6, 0.2, 10.0
            time_window = (0, args.window_end)

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
        ET.SubElement(rect, "length").text = f"{goal_length:.4f}"
        ET.SubElement(rect, "width").text = f"{width:.4f}"
        ET.SubElement(rect, "orientation").text = f"{heading:.5f}"
        c = ET.SubElement(rect, "center")
        ET.SubElement(c, "x").text = f"{gx:.4f}"
        ET.SubElement(c, "y").text = f"{gy:.4f}"
        interval(gs, "orientation", heading - heading_tol, heading + heading_tol)
        interval(gs, "time", time_window[0], time_window[1], integer=True)
        interval(gs, "velocity", max(0.0, v_goal - v_tol), v_goal + v_tol)
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
