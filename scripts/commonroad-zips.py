#!/usr/bin/env python3
"""Zipper merges with new traffic, on the road of a shared `ZAM_Zip` file, for probing the planner
beyond the three shared ones.

The road (its lanelets) is read from ROAD.xml: two lanes (25 left, 26 right) that converge over
27 and 28 into the one lane 24. Each seed draws 2-4 cars, each following its lane's centre (25,
28, 24 or 26, 27, 24) with the intelligent driver model: it keeps a time gap of 1-1.6 s to the
car ahead on its way, and in the merge (the last 35 m of 25 and 26, then 27 and 28) to the car
ahead on either way, as a zipper does; the cars do not react to the ego, as in a recording. The
ego starts in either lane 100-125 m before the merge, at 5-15 m/s, at least 10 m from a car in
its lane. The goal, at steps 84-85 like the shared files': lanelet 24 (merged), 26 or 25 (not yet
at the merge) or 27 and 28 (in it), with the speed from 0 to 5-16 m/s above the ego's start.
Whether a way through exists is not known when written: `frenetic commonroad --way-through`
tells.

    scripts/commonroad-zips.py ROAD.xml OUT_DIR [--seeds 1-40]

writes OUT_DIR/ZAM_Zip-9_<seed>_T-1.xml. The files are test inputs made from the shared data at
run time: not part of the tree.
"""
import argparse
import bisect
import math
import os
import random
import xml.etree.ElementTree as ET

DT = 0.1
STEPS = 85


def bound(lanelet, side):
    return [(float(p.find('x').text), float(p.find('y').text))
            for p in lanelet.findall(f'{side}/point')]


def resample(pts, n):
    """n points evenly spaced along the polyline pts."""
    acc = [0.0]
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        acc.append(acc[-1] + math.hypot(x1 - x0, y1 - y0))
    out = []
    for q in range(n):
        s = acc[-1] * q / (n - 1)
        i = min(max(bisect.bisect_right(acc, s) - 1, 0), len(pts) - 2)
        f = (s - acc[i]) / max(acc[i + 1] - acc[i], 1e-9)
        out.append((pts[i][0] + f * (pts[i + 1][0] - pts[i][0]),
                    pts[i][1] + f * (pts[i + 1][1] - pts[i][1])))
    return out


def centre(lanelet):
    left, right = resample(bound(lanelet, 'leftBound'), 40), resample(bound(lanelet, 'rightBound'), 40)
    return [((a[0] + b[0]) / 2, (a[1] + b[1]) / 2) for a, b in zip(left, right)]


class Way:
    """A lane's centre as a polyline with arc length."""

    def __init__(self, pts):
        self.pts = [pts[0]]
        for p in pts[1:]:
            if math.hypot(p[0] - self.pts[-1][0], p[1] - self.pts[-1][1]) > 1e-6:
                self.pts.append(p)
        self.acc = [0.0]
        for (x0, y0), (x1, y1) in zip(self.pts, self.pts[1:]):
            self.acc.append(self.acc[-1] + math.hypot(x1 - x0, y1 - y0))

    def at(self, s):
        """(x, y, heading) at arc length s (extended straight past the ends)."""
        i = min(max(bisect.bisect_right(self.acc, s) - 1, 0), len(self.pts) - 2)
        (x0, y0), (x1, y1) = self.pts[i], self.pts[i + 1]
        seg = self.acc[i + 1] - self.acc[i]
        f = (s - self.acc[i]) / seg
        return x0 + f * (x1 - x0), y0 + f * (y1 - y0), math.atan2(y1 - y0, x1 - x0)

    def s_of_x(self, x):
        lo, hi = -500.0, self.acc[-1] + 500.0
        for _ in range(60):
            mid = (lo + hi) / 2
            if self.at(mid)[0] < x:
                lo = mid
            else:
                hi = mid
        return lo


def simulate(cars, ways, merge_x):
    """IDM; cars: dicts with way, s, v, v0, T. Returns per car the list of (x, y, h, v, a)."""
    out = [[] for _ in cars]
    for k in range(STEPS + 1):
        pos = [ways[c['way']].at(c['s']) for c in cars]
        accs = []
        for i, c in enumerate(cars):
            gap = math.inf
            dv = 0.0
            for j, o in enumerate(cars):
                if j == i:
                    continue
                same = o['way'] == c['way']
                merging = pos[i][0] > merge_x and pos[j][0] > merge_x
                if not (same or merging):
                    continue
                ahead = (o['s'] - c['s']) if same else (pos[j][0] - pos[i][0])
                if ahead <= 0:
                    continue
                g = ahead - 5.0
                if g < gap:
                    gap, dv = g, c['v'] - o['v']
            free = 1 - (c['v'] / c['v0']) ** 4
            a_max, b = 1.5, 2.0
            if gap < math.inf:
                star = 2.0 + max(0.0, c['v'] * c['T'] + c['v'] * dv / (2 * math.sqrt(a_max * b)))
                acc = a_max * (free - (star / max(gap, 0.5)) ** 2)
            else:
                acc = a_max * free
            accs.append(max(-8.0, min(acc, a_max)))
        for i, c in enumerate(cars):
            x, y, h = pos[i]
            out[i].append((x, y, h, c['v'], accs[i]))
            v = max(0.0, c['v'] + accs[i] * DT)
            c['s'] += (c['v'] + v) / 2 * DT
            c['v'] = v
    return out


def state_xml(x, y, h, v, a, k, initial):
    s = (f'<position><point><x>{x:.4f}</x><y>{y:.4f}</y></point></position><orientation><exact>'
         f'{h:.5f}</exact></orientation><time><exact>{k}</exact></time><velocity><exact>{v:.4f}'
         f'</exact></velocity>')
    if initial:
        s += (f'<acceleration><exact>{a:.4f}</exact></acceleration><yawRate><exact>0</exact>'
              '</yawRate><slipAngle><exact>0</exact></slipAngle>')
    return s


def scenario(root, ways, merge_x, seed):
    """One seed's file; merge_x: where the cars start to zip (35 m before the lanes converge)."""
    rng = random.Random(seed)
    cars = []
    for _ in range(rng.randint(2, 4)):
        for _try in range(50):
            w = rng.choice('LR')
            s = ways[w].s_of_x(rng.uniform(-140, -50))
            if all(c['way'] != w or abs(c['s'] - s) > 15 for c in cars):
                v = rng.uniform(4, 18)
                cars.append({'way': w, 's': s, 'v': v, 'v0': max(v, rng.uniform(10, 22)),
                             'T': rng.uniform(1.0, 1.6)})
                break
    for _try in range(200):
        ego_w = rng.choice('LR')
        ego_s = ways[ego_w].s_of_x(rng.uniform(-125, -100))
        if all(c['way'] != ego_w or abs(c['s'] - ego_s) > 10 for c in cars):
            break
    ego_v = rng.uniform(5, 15)
    tracks = simulate(cars, ways, merge_x)
    obstacles = ''
    for i, tr in enumerate(tracks):
        states = ''.join(f'<state>{state_xml(*tr[k][:4], 0, k, False)}</state>'
                         for k in range(1, len(tr)))
        obstacles += (f'<dynamicObstacle id="{100 + i}"><type>car</type><shape><rectangle>'
                      '<length>5.0</length><width>2.0</width></rectangle></shape><initialState>'
                      f'{state_xml(*tr[0], 0, True)}</initialState><trajectory>{states}'
                      '</trajectory></dynamicObstacle>\n')
    goal_lanelets = rng.choice([['24'], ['26'], ['25'], ['27', '28'], ['24']])
    vmax = ego_v + rng.uniform(5, 16)
    goal = ('<goalState><position>' + ''.join(f'<lanelet ref="{g}"/>' for g in goal_lanelets)
            + f'</position><time><intervalStart>{STEPS - 1}</intervalStart><intervalEnd>{STEPS}'
            f'</intervalEnd></time><velocity><intervalStart>0.0</intervalStart><intervalEnd>'
            f'{vmax:.4f}</intervalEnd></velocity></goalState>')
    x, y, h = ways[ego_w].at(ego_s)
    problem = (f'<planningProblem id="35"><initialState>{state_xml(x, y, h, ego_v, 0, 0, True)}'
               f'</initialState>{goal}</planningProblem>')
    lanelets = ''.join(ET.tostring(e, encoding='unicode')
                       for e in root.findall('lanelet') + root.findall('trafficSign'))
    return ('<?xml version="1.0" encoding="UTF-8"?>\n<commonRoad timeStepSize="0.1" '
            'commonRoadVersion="2020a" author="frenetic" affiliation="frenetic" source="hand-made" '
            f'benchmarkID="ZAM_Zip-9_{seed}_T-1" date="2026-12-02">\n' + lanelets + obstacles
            + problem + '\n</commonRoad>\n')


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('road', help='a shared ZAM_Zip file (its lanelets 24-28 are used)')
    ap.add_argument('out_dir', help='directory for the files (created if missing)')
    ap.add_argument('--seeds', default='1-40', help='seeds, FIRST-LAST (default: 1-40)')
    args = ap.parse_args()
    try:
        root = ET.parse(args.road).getroot()
    except (OSError, ET.ParseError) as e:
        raise SystemExit(f'{args.road}: {e}')
    lan = {l.get('id'): l for l in root.findall('lanelet')}
    for need in ('24', '25', '26', '27', '28'):
        if need not in lan:
            raise SystemExit(f'{args.road}: no lanelet {need}: not a ZAM_Zip road')
    ways = {'L': Way(centre(lan['25']) + centre(lan['28']) + centre(lan['24'])),
            'R': Way(centre(lan['26']) + centre(lan['27']) + centre(lan['24']))}
    merge_x = centre(lan['28'])[0][0] - 35.0  # 35 m before the lanes start to converge
    try:
        first, last = (int(v) for v in args.seeds.split('-'))
    except ValueError:
        raise SystemExit(f'--seeds {args.seeds}: expected FIRST-LAST, e.g. 1-40')
    os.makedirs(args.out_dir, exist_ok=True)
    for seed in range(first, last + 1):
        with open(os.path.join(args.out_dir, f'ZAM_Zip-9_{seed}_T-1.xml'), 'w') as f:
            f.write(scenario(root, ways, merge_x, seed))


if __name__ == '__main__':
    main()
