#!/usr/bin/env python3
"""Hand-made CommonRoad 2020a problems at motorway ramps, for probing the road builder.

Two 3.5 m lanes along +x (lanelet 1 right, 2 left, x 0-200; then 3 left and 4 right, x 200-500)
and one of four junctions:
  exit      the right lane splits at x = 200 into 4 (straight on) and the ramp 5, which starts on
            top of 4 and bends off to the right (0.0002 (x - 200)^2 m); the goal is lanelet 5,
            the ego starts in the left lane;
  straight  the same split, the goal is lanelet 4, the ego starts in the right lane;
  exitleft  the split mirrored: the ramp bends off the left lane to the left, the ego starts in
            the right lane;
  exitcurve the split with a ramp on an arc of 150 m radius turning right (1.2 rad); the goal is
            a 10 m box at its end;
  exitb     a deceleration lane 6 (x 120-220, adjacent right of 4) goes on as the ramp 7; the
            goal is 7, the ego starts in the left lane;
  entry     an acceleration lane 5 (x 0-200, adjacent right of 1) ends at x = 200; the ego starts
            on it, the goal is lanelet 4;
  entrymain the same road, the ego starts in the right lane, the goal is lanelet 4, and cars on
            the acceleration lane (with traffic) move into the right lane over the 3 s before
            its end (an exiD entry seen from the motorway).
Traffic (seed > 0): cars at 22-30 m/s in both lanes, 30-70 m apart, each at constant speed
along its lane (none within 12 m of the ego's start in its lane); seed 0: none.

  scripts/commonroad-ramps.py OUT_DIR [--speeds 15 25 32] [--seeds 0 1 2 3 4 5 6]
  [--opens STEP]
writes OUT_DIR/<kind>_v<speed>_<seed>.xml for every kind, ego speed (m/s) and seed. The goal's
window runs from step STEP (default 0) to max(200, STEP + 100) (exitcurve: 250).
"""
import argparse
import math
import os
import random

W = 3.5


def points(xs, f):
    return ''.join(f'<point><x>{x:.4f}</x><y>{f(x):.4f}</y></point>' for x in xs)


def lanelet(i, xs, left, right, pred=(), succ=(), al=None, ar=None, left_marking='dashed'):
    """Bounds as functions of x at xs, or (xs None) as lists of (x, y) points."""
    def bound(b):
        if xs is not None:
            return points(xs, b)
        return ''.join(f'<point><x>{x:.4f}</x><y>{y:.4f}</y></point>' for x, y in b)
    s = (f'<lanelet id="{i}"><leftBound>{bound(left)}<lineMarking>{left_marking}</lineMarking>'
         f'</leftBound><rightBound>{bound(right)}<lineMarking>solid</lineMarking></rightBound>')
    s += ''.join(f'<predecessor ref="{p}"/>' for p in pred)
    s += ''.join(f'<successor ref="{p}"/>' for p in succ)
    if al:
        s += f'<adjacentLeft ref="{al}" drivingDir="same"/>'
    if ar:
        s += f'<adjacentRight ref="{ar}" drivingDir="same"/>'
    return s + '<laneletType>interstate</laneletType></lanelet>\n'


def motorway(succ1=(4,), succ2=(3,), ar1=None, ar4=None, fork=200):
    """The two lanes: 1 (right) and 2 (left) up to x = 200 (1 up to `fork`), then 3 (left) and
    4 (right) to x = 500."""
    x0, x1 = range(0, 201, 10), range(200, 501, 10)
    return [lanelet(1, range(0, fork + 1, 10), lambda x: 0, lambda x: -W, succ=succ1, al=2, ar=ar1),
            lanelet(2, x0, lambda x: W, lambda x: 0, succ=succ2, ar=1),
            lanelet(3, x1, lambda x: W, lambda x: 0, pred=(2,), ar=4),
            lanelet(4, range(fork, 501, 10), lambda x: 0, lambda x: -W, pred=(1,), al=3, ar=ar4)]


OPENS = 0  # the goal window's first step (--opens)
KINDS = ['exit', 'straight', 'exitleft', 'exitcurve', 'exitb', 'entry', 'entrymain']


def goal_lanelet(i):
    return (f'<goalState><time><intervalStart>{OPENS}</intervalStart><intervalEnd>'
            f'{max(200, OPENS + 100)}</intervalEnd></time>'
            f'<position><lanelet ref="{i}"/></position></goalState>')


def road(kind):
    """The lanelets, the goal and the ego's start y of one kind."""
    ramp = range(200, 401, 10)
    if kind in ('exit', 'straight'):
        def off(x):
            return -0.0002 * (x - 200) ** 2
        out = motorway(succ1=(4, 5))
        out.append(lanelet(5, ramp, off, lambda x: off(x) - W, pred=(1,)))
        return out, goal_lanelet(5 if kind == 'exit' else 4), (W / 2 if kind == 'exit' else -W / 2)
    if kind == 'exitleft':
        def off(x):
            return 0.0002 * (x - 200) ** 2
        out = motorway(succ2=(3, 5))
        out.append(lanelet(5, ramp, lambda x: off(x) + W, off, pred=(2,)))
        return out, goal_lanelet(5), -W / 2
    if kind == 'exitcurve':
        # The ramp 5 leaves the right lane at x = 200 on an arc of radius 150 m turning right
        # (1.2 rad); the goal is a 10 m box at its end.
        radius, sweep, n = 150.0, 1.2, 40
        def arc(offset):  # offset: left of the ramp's centre line, m
            return [(200 + (radius + offset) * math.sin(sweep * q / n),
                     -W / 2 - radius + (radius + offset) * math.cos(sweep * q / n))
                    for q in range(n + 1)]
        out = motorway(succ1=(4, 5))
        out.append(lanelet(5, None, arc(W / 2), arc(-W / 2), pred=(1,), left_marking='solid'))
        a = sweep - 10 / radius
        cx, cy = 200 + radius * math.sin(a), -W / 2 - radius + radius * math.cos(a)
        goal = (f'<goalState><time><intervalStart>{OPENS}</intervalStart><intervalEnd>'
                f'{max(250, OPENS + 100)}</intervalEnd>'
                f'</time><position><rectangle><length>10</length><width>3</width><orientation>'
                f'{-a:.4f}</orientation><center><x>{cx:.4f}</x><y>{cy:.4f}</y></center></rectangle>'
                '</position></goalState>')
        return out, goal, W / 2
    if kind == 'exitb':
        def off(x):
            return -0.0002 * (x - 220) ** 2
        out = motorway(fork=120, ar4=6)
        out.append(lanelet(6, range(120, 221, 10), lambda x: -W, lambda x: -2 * W, succ=(7,), al=4))
        out.append(lanelet(7, range(220, 421, 10), lambda x: off(x) - W, lambda x: off(x) - 2 * W,
                           pred=(6,)))
        return out, goal_lanelet(7), W / 2
    if kind in ('entry', 'entrymain'):
        x0 = range(0, 201, 10)
        return ([lanelet(5, x0, lambda x: -W, lambda x: -2 * W, al=1)] + motorway(ar1=5),
                goal_lanelet(4), -1.5 * W if kind == 'entry' else -W / 2)
    raise ValueError(kind)


def state(x, y, v, k, h=0.0):
    return (f'<position><point><x>{x:.3f}</x><y>{y:.4f}</y></point></position><orientation><exact>'
            f'{h:.5f}</exact></orientation><time><exact>{k}</exact></time><velocity><exact>{v:.3f}'
            '</exact></velocity>')


def car_xml(i, xs, ys, v):
    """A car of 4.5 x 1.8 m at the points xs, ys (one per step), at speed v."""
    def heading(k):
        k1 = min(k + 1, len(xs) - 1)
        k0 = k1 - 1
        return math.atan2(ys[k1] - ys[k0], xs[k1] - xs[k0])
    trajectory = ''.join(f'<state>{state(xs[k], ys[k], v, k, heading(k))}</state>'
                         for k in range(1, len(xs)))
    return (f'<dynamicObstacle id="{i}"><type>car</type><shape><rectangle>'
            '<length>4.5</length><width>1.8</width></rectangle></shape><initialState>'
            f'{state(xs[0], ys[0], v, 0, heading(0))}<yawRate><exact>0</exact></yawRate><slipAngle>'
            f'<exact>0</exact></slipAngle></initialState><trajectory>{trajectory}'
            '</trajectory></dynamicObstacle>\n')


def scenario(kind, speed, seed):
    lanes, goal, y0 = road(kind)
    cars = []
    if seed > 0:
        rng = random.Random(seed)
        for lane_y in (W / 2, -W / 2):
            x = rng.uniform(-40, 20)
            while x < 250:
                v = rng.uniform(22, 30)
                if abs(x - 20) > 12 or abs(lane_y - y0) > 1:
                    cars.append(car_xml(100 + len(cars), [x + v * 0.1 * k for k in range(150)],
                                        [lane_y] * 150, v))
                x += rng.uniform(30, 70)
        if kind == 'entrymain':
            # Cars on the acceleration lane, each moving into the right lane over the 3 s before
            # its end (x = 200), at constant speed.
            x = rng.uniform(-60, 0)
            while x < 150:
                v = rng.uniform(18, 28)
                xs = [x + v * 0.1 * k for k in range(150)]
                start = 200 - 3 * v - 2.25
                ys = [-1.5 * W + W * min(max((px - start) / (3 * v), 0.0), 1.0) for px in xs]
                if abs(x - 20) > 12:
                    cars.append(car_xml(100 + len(cars), xs, ys, v))
                x += rng.uniform(30, 70)
    problem = (f'<planningProblem id="1"><initialState>{state(20, y0, speed, 0)}<yawRate><exact>0'
               '</exact></yawRate><slipAngle><exact>0</exact></slipAngle></initialState>'
               f'{goal}</planningProblem>')
    return ('<?xml version="1.0" encoding="UTF-8"?>\n<commonRoad timeStepSize="0.1" '
            'commonRoadVersion="2020a" author="frenetic" affiliation="frenetic" source="hand-made" '
            f'benchmarkID="ZAM_{kind.capitalize()}-{int(speed)}_{seed}_T-1" date="2026-11-30">\n'
            + ''.join(lanes) + ''.join(cars) + problem + '\n</commonRoad>\n')


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('out_dir', help='directory for the files (created if missing)')
    ap.add_argument('--speeds', type=float, nargs='+', default=[15, 25, 32],
                    help="the ego's initial speeds, m/s (default: 15 25 32)")
    ap.add_argument('--seeds', type=int, nargs='+', default=list(range(7)),
                    help='traffic seeds, 0 = no traffic (default: 0-6)')
    ap.add_argument('--opens', type=int, default=0,
                    help="the goal window's first step (0.1 s steps; default: 0). A window that "
                         "opens late makes the ego wait in a goal at the map's end")
    ap.add_argument('--kinds', nargs='+', default=KINDS[:-1], choices=KINDS,
                    help='the junctions to write (default: all but entrymain, the set of '
                         'docs/commonroad.md)')
    args = ap.parse_args()
    global OPENS
    OPENS = args.opens
    os.makedirs(args.out_dir, exist_ok=True)
    for kind in args.kinds:
        for speed in args.speeds:
            for seed in args.seeds:
                path = os.path.join(args.out_dir, f'{kind}_v{int(speed)}_{seed}.xml')
                with open(path, 'w') as f:
                    f.write(scenario(kind, speed, seed))


if __name__ == '__main__':
    main()
