// The frenetic report's script, part 3 of 7 (see core.js): the road and the goal regions as
// paths in the map frame, built once for the replay. A drive's road is a band of lanes beside
// its centre line; a CommonRoad run's is its lanes' recorded borders.

// Offset polylines of the centre line: d > 0 lies to the right of the driving direction, i.e.
// along (ty, -tx) for a unit tangent (tx, ty) in the map frame (x east, y north).
const CX = D.center.x, CY = D.center.y;
const closed = CX.length > 2 &&
    Math.hypot(CX[0] - CX[CX.length - 1], CY[0] - CY[CY.length - 1]) < 20;
function offsetLine(d) {
  const n = CX.length, xs = new Float64Array(n), ys = new Float64Array(n);
  for (let i = 0; i < n; ++i) {
    const a = closed ? (i - 1 + n) % n : Math.max(i - 1, 0);
    const b = closed ? (i + 1) % n : Math.min(i + 1, n - 1);
    let tx = CX[b] - CX[a], ty = CY[b] - CY[a];
    const len = Math.hypot(tx, ty) || 1;
    tx /= len; ty /= len;
    xs[i] = CX[i] + d * ty;
    ys[i] = CY[i] - d * tx;
  }
  return [xs, ys];
}
function linePath(xs, ys) {
  const p = new Path2D();
  for (let i = 0; i < xs.length; ++i) (i ? p.lineTo : p.moveTo).call(p, xs[i], ys[i]);
  if (closed) p.closePath();
  return p;
}
// surface: filled; center and edge: solid lines; lanes: dashed lines; ends: solid lines across.
const road = { surface: null, center: null, lanes: [], edge: null, ends: null };
if (CX.length > 1) {
  const outer = offsetLine(H.lanes * H.lane_width);
  // Centre line forward and the outer edge backward: one polygon whose non-zero winding
  // covers exactly the band between them, for a loop as for an open road.
  const s = new Path2D();
  for (let i = 0; i < CX.length; ++i) (i ? s.lineTo : s.moveTo).call(s, CX[i], CY[i]);
  for (let i = CX.length - 1; i >= 0; --i) s.lineTo(outer[0][i], outer[1][i]);
  s.closePath();
  road.surface = s;
  road.center = linePath(CX, CY);
  for (let l = 1; l < H.lanes; ++l) road.lanes.push(linePath(...offsetLine(l * H.lane_width)));
  road.edge = linePath(outer[0], outer[1]);
}
const GOALS = [];
if (COMMONROAD) {
  // Each lane's borders as recorded (lanes may begin, end, widen and bend apart): the leftmost
  // lane's left border solid yellow, the rightmost's right border solid white, every border
  // dashed, and a solid line across each lane where it begins and ends, so that the road's end
  // shows where the network ends. Goal regions as outlines.
  if (Array.isArray(D.road) && D.road.length) {
    road.surface = new Path2D();
    road.center = new Path2D();
    road.edge = new Path2D();
    road.ends = new Path2D();
    D.road.forEach((l, i) => {
      const n = Math.min(l.lx.length, l.ly.length, l.rx.length, l.ry.length);
      if (n < 2) return;
      for (let p = 0; p < n; ++p) (p ? road.surface.lineTo : road.surface.moveTo).call(road.surface, l.lx[p], l.ly[p]);
      for (let p = n - 1; p >= 0; --p) road.surface.lineTo(l.rx[p], l.ry[p]);
      road.surface.closePath();
      const left = linePath(l.lx, l.ly), right = linePath(l.rx, l.ry);
      road.lanes.push(left, right);
      if (i === 0) road.center.addPath(left);
      if (i === D.road.length - 1) road.edge.addPath(right);
      for (const p of [0, n - 1]) {
        road.ends.moveTo(l.lx[p], l.ly[p]);
        road.ends.lineTo(l.rx[p], l.ry[p]);
      }
    });
  }
  for (const g of (Array.isArray(D.goals) ? D.goals : [])) {
    if (g.x.length < 2) continue;
    const p = linePath(g.x, g.y);
    p.closePath();
    GOALS.push({ path: p, steps: g.steps });
  }
}
