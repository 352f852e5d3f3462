// The frenetic report's script, part 4 of 7 (see core.js): the top-down replay of one cycle
// (road, goal regions, the cycle's candidates, the path sent, traffic and the ego, centred on
// the ego) and its legend.

// ---------- candidates ----------
const CAND = D.candidates;
const REJECT_COLOR = "rgba(230,230,230,0.55)";
// The kept cycle shown at exchange k: the last one at or before k, if less than 1 s older.
function candidateCycleAt(k) {
  const j = lastAtOrBefore(CAND, k, (c) => c.e);
  if (j < 0) return null;
  const c = CAND[j];
  return T[k] - T[c.e] <= 1.0 ? c : null;
}
function costColor(u) {  // 0 cheapest (green) .. 1 dearest (red)
  return `hsl(${Math.round(120 * (1 - clamp(u, 0, 1)))}, 85%, 50%)`;
}

// ---------- replay ----------
const canvas = $("replay");
const ctx = canvas.getContext("2d");
let dpr = window.devicePixelRatio || 1;
function resizeReplay() {
  dpr = window.devicePixelRatio || 1;
  canvas.width = Math.max(1, Math.round(canvas.clientWidth * dpr));
  canvas.height = Math.max(1, Math.round(canvas.clientHeight * dpr));
}
function box(c, x, y, headingRad, length, width) {
  const ch = Math.cos(headingRad), sh = Math.sin(headingRad);
  const hl = length / 2, hw = width / 2;
  c.beginPath();
  const corners = [[hl, hw], [hl, -hw], [-hl, -hw], [-hl, hw]];
  corners.forEach(([a, b], i) => {
    const px = x + a * ch - b * sh, py = y + a * sh + b * ch;
    if (i) c.lineTo(px, py); else c.moveTo(px, py);
  });
  c.closePath();
}
function drawReplay() {
  const k = state.k;
  const W = canvas.width, Hh = canvas.height;
  const z = state.zoom * dpr;  // px per m
  const ex = E.x[k], ey = E.y[k];
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.fillStyle = "#3d7a3a";
  ctx.fillRect(0, 0, W, Hh);
  // World to screen: centred on the ego, y up.
  const toScreen = (x, y) => [W / 2 + (x - ex) * z, Hh / 2 - (y - ey) * z];
  ctx.setTransform(z, 0, 0, -z, W / 2 - ex * z, Hh / 2 + ey * z);
  const px = 1 / z;  // one device pixel in m
  if (road.surface) {
    ctx.fillStyle = "#505459";
    ctx.fill(road.surface);
    ctx.lineWidth = 2 * px * dpr;
    ctx.strokeStyle = "#f5c518";
    ctx.setLineDash([]);
    ctx.stroke(road.center);
    ctx.strokeStyle = "#ffffff";
    ctx.stroke(road.edge);
    if (road.ends) ctx.stroke(road.ends);
    ctx.lineWidth = 1.5 * px * dpr;
    ctx.setLineDash([3, 6]);  // m: like road markings
    for (const p of road.lanes) ctx.stroke(p);
    ctx.setLineDash([]);
  }
  // Goal regions (a CommonRoad run's): filled more strongly inside their time window.
  for (const g of GOALS) {
    const step = T[k] / H.dt;
    const open = !g.steps || (step >= g.steps[0] - 1e-6 && step <= g.steps[1] + 1e-6);
    ctx.fillStyle = open ? "rgba(18,183,106,0.35)" : "rgba(18,183,106,0.12)";
    ctx.fill(g.path);
    ctx.strokeStyle = "#12b76a";
    ctx.lineWidth = 1.5 * px * dpr;
    ctx.stroke(g.path);
  }
  const labels = [];
  // Candidates of the cycle (decimated by the writer), the rejected ones faint.
  const cyc = state.showCandidates ? candidateCycleAt(k) : null;
  if (cyc) {
    let lo = Infinity, hi = -Infinity;
    for (const c of cyc.c) if (!c[5] && num(c[3])) { lo = Math.min(lo, c[3]); hi = Math.max(hi, c[3]); }
    // Rejected ones underneath, then dearest to cheapest, the winner on top.
    const rank = (c) => (c[4] & 2) ? 2 : c[5] ? 0 : 1;
    const order = cyc.c.map((c, i) => i).sort((a, b) => rank(cyc.c[a]) - rank(cyc.c[b]) ||
                                                        cyc.c[b][3] - cyc.c[a][3]);
    for (const i of order) {
      const c = cyc.c[i];
      const xs = c[6], ys = c[7];
      if (xs.length < 2) continue;
      ctx.beginPath();
      for (let p = 0; p < xs.length; ++p) (p ? ctx.lineTo : ctx.moveTo).call(ctx, xs[p], ys[p]);
      const winner = (c[4] & 2) !== 0;
      if (c[5]) {
        ctx.strokeStyle = REJECT_COLOR;
        ctx.setLineDash([4 * px * dpr, 4 * px * dpr]);
        ctx.lineWidth = 1.2 * px * dpr;
        labels.push([xs[xs.length - 1], ys[ys.length - 1], c[5], "rgba(255,255,255,0.75)"]);
      } else {
        ctx.strokeStyle = costColor(hi > lo ? (c[3] - lo) / (hi - lo) : 0);
        ctx.setLineDash([]);
        ctx.lineWidth = (winner ? 4 : 1.8) * px * dpr;
      }
      ctx.stroke();
      ctx.setLineDash([]);
      if (winner) labels.push([xs[xs.length - 1], ys[ys.length - 1], "winner " + fmt(c[3]), "#fff"]);
    }
  }
  // The path sent.
  const p0 = D.path.off[k], p1 = D.path.off[k + 1];
  if (p1 - p0 > 1) {
    ctx.beginPath();
    for (let p = p0; p < p1; ++p) (p > p0 ? ctx.lineTo : ctx.moveTo).call(ctx, D.path.x[p], D.path.y[p]);
    ctx.strokeStyle = "#22d3ee";
    ctx.lineWidth = 2.5 * px * dpr;
    ctx.stroke();
  }
  // Traffic and ego.
  const yaw = E.yaw[k] * Math.PI / 180;
  const t0 = D.traffic.off[k], t1 = D.traffic.off[k + 1];
  for (let j = t0; j < t1; ++j) {
    const h = D.traffic.h[j];
    // A CommonRoad run's cars are each of its recorded size; a drive's all of the header's.
    box(ctx, D.traffic.x[j], D.traffic.y[j], num(h) ? h * Math.PI / 180 : yaw,
        COMMONROAD && D.traffic.l && num(D.traffic.l[j]) ? D.traffic.l[j] : H.car_length,
        COMMONROAD && D.traffic.w && num(D.traffic.w[j]) ? D.traffic.w[j] : H.car_width);
    ctx.fillStyle = "#d0d5dd";
    ctx.fill();
    ctx.lineWidth = 1 * px * dpr;
    ctx.strokeStyle = "#101828";
    ctx.stroke();
    labels.push([D.traffic.x[j], D.traffic.y[j], String(D.traffic.id[j]), "#101828", true]);
  }
  box(ctx, ex, ey, yaw, H.car_length, H.car_width);
  const hit = D.incidents.some((i) => Math.abs(i.e - k) <= 2);
  ctx.fillStyle = hit ? "#f04438" : "#12b76a";
  ctx.fill();
  ctx.strokeStyle = "#fff";
  ctx.stroke();
  // Labels in screen space, so text stays upright and readable at every zoom.
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.font = `${11 * dpr}px system-ui, sans-serif`;
  ctx.textAlign = "center";
  ctx.textBaseline = "middle";
  for (const [x, y, text, color, onCar] of labels) {
    const [sx, sy] = toScreen(x, y);
    ctx.fillStyle = color;
    ctx.fillText(text, sx, sy + (onCar ? 0 : -8 * dpr));
  }
  ctx.textAlign = "left";
  ctx.textBaseline = "top";
  ctx.fillStyle = "rgba(0,0,0,0.55)";
  ctx.fillRect(6 * dpr, 6 * dpr, 300 * dpr, 54 * dpr);
  ctx.fillStyle = "#fff";
  const st = E.status[k] >= 0 ? D.status_names[E.status[k]] : DASH;
  ctx.fillText(`t ${fmt(T[k], 2)} s   cycle ${E.i[k]}   ${fmt(E.speed[k], 1)} mph   lane ${E.lane[k]}`,
               12 * dpr, 10 * dpr);
  ctx.fillText(`plan ${st}, ${fmt(E.ms[k], 2)} ms, feasible ${E.feasible[k]}/${E.checked[k]} checked`,
               12 * dpr, 26 * dpr);
  ctx.fillText(cyc ? `candidates of cycle ${E.i[cyc.e]}: ${cyc.c.length} of ${cyc.listed}`
                   : (state.showCandidates ? "no candidates kept near this cycle" : ""),
               12 * dpr, 42 * dpr);
  if (hit) {
    ctx.fillStyle = "#f04438";
    ctx.fillText("INCIDENT", W - 80 * dpr, 10 * dpr);
  }
}
$("replay-legend").innerHTML =
    '<span><i class="swatch" style="background:#12b76a"></i>ego</span>' +
    '<span><i class="swatch" style="background:#d0d5dd"></i>traffic (id)</span>' +
    '<span><i class="swatch" style="background:#22d3ee"></i>path sent</span>' +
    '<span><i class="swatch" style="background:linear-gradient(90deg,hsl(120,85%,50%),hsl(0,85%,50%))"></i>' +
    'candidates, cheap to dear</span>' +
    '<span><i class="swatch" style="background:#ddd"></i>rejected (reason)</span>';
if (COMMONROAD) {
  $("replay-legend").innerHTML +=
      '<span><i class="swatch" style="background:rgba(18,183,106,0.35);border:1px solid #12b76a"></i>' +
      'goal region (strong inside its time window)</span>';
}
