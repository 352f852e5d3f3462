#!/usr/bin/env python3
"""Writes a CommonRoad scenario turned by ANGLE (rad, about the origin) and then moved by (DX, DY)
metres: every point and centre (lanelet bounds, obstacle and problem states, goal shapes) and
every orientation (states, intervals, goal rectangles); an obstacle's shape, in the obstacle's
own frame, stays. Speeds, sizes and times stay. A planner that
depends on where the road lies or which way it points solves the transformed file differently:
run a set both ways and compare (docs/commonroad.md, "Moved, turned, and new problems").

    scripts/commonroad-transform.py IN.xml|IN_DIR OUT_DIR --angle 3.0 --dx -20000 --dy 35000

The written files are test inputs made from the shared data at run time: not part of the tree.
"""
import argparse
import math
import sys
import xml.etree.ElementTree as ET

from scenario_files import rewrite_each, scenario_files


def transform(src, dst, angle, dx, dy):
    c, s = math.cos(angle), math.sin(angle)
    tree = ET.parse(src)
    root = tree.getroot()

    def move(node):
        x, y = node.find("x"), node.find("y")
        if x is None or y is None:
            return
        px, py = float(x.text), float(y.text)
        x.text = repr(c * px - s * py + dx)
        y.text = repr(s * px + c * py + dy)

    # An obstacle's <shape> is in the obstacle's own frame (its states place and turn it): it
    # stays as it is. Everything else is in the scenario's frame.
    local = set()
    for obstacle in root:
        if obstacle.tag.endswith("Obstacle"):
            for shape in obstacle.findall("shape"):
                local.update(shape.iter())
    for tag in ("point", "center"):
        for node in root.iter(tag):
            if node not in local:
                move(node)
    for node in root.iter("orientation"):
        if node in local:
            continue
        children = list(node)
        if not children:  # a rectangle's
            node.text = repr(float(node.text) + angle)
        for child in children:
            if child.tag in ("exact", "intervalStart", "intervalEnd"):
                child.text = repr(float(child.text) + angle)
    tree.write(dst, encoding="utf-8", xml_declaration=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("source", help="a scenario file or a directory of them")
    ap.add_argument("out_dir")
    ap.add_argument("--angle", type=float, default=0.0, help="rad, counter-clockwise (default 0)")
    ap.add_argument("--dx", type=float, default=0.0, help="m (default 0)")
    ap.add_argument("--dy", type=float, default=0.0, help="m (default 0)")
    a = ap.parse_args()
    return rewrite_each(scenario_files(a.source), a.out_dir,
                        lambda src, dst: transform(src, dst, a.angle, a.dx, a.dy))


if __name__ == "__main__":
    sys.exit(main())
