// The frenetic drive report: reads the JSON embedded by `frenetic report` (format
// "frenetic-report" v1, written by src/report/page.cc) and draws a replay, plots over time and
// per-cycle cost tables with plain canvas code (no library, works offline).
"use strict";
(function () {
  const D = JSON.parse(document.getElementById("frenetic-data").textContent);
  const E = D.ex;
  const N = D.n;
  const H = D.header;
  const T = E.t;
  const DASH = "\u2013";
  const MPH = 0.44704;
  //@commonroad
  const CAP = ((H.config || {}).limits || {}).max_speed_mph;  // mph: the planner's speed cap
  //@end

  // ---------- small helpers ----------
  function $(id) { return document.getElementById(id); }
  function el(tag, attrs, ...children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === "class") e.className = v;
      else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
      else e.setAttribute(k, v);
    }
    for (const c of children) {
      if (c === null || c === undefined) continue;
      e.append(c instanceof Node ? c : String(c));
    }
    return e;
  }
  function num(v) { return typeof v === "number" && isFinite(v); }
  function fmt(v, digits) {
    if (!num(v)) return DASH;
    if (digits === undefined) {
      const a = Math.abs(v);
      digits = a >= 100 ? 0 : a >= 10 ? 1 : a >= 1 ? 2 : 3;
    }
    return v.toFixed(digits);
  }
  function clamp(v, lo, hi) { return Math.max(lo, Math.min(hi, v)); }
  // Last index i with a[i] <= v (a sorted), or -1.
  function lastAtOrBefore(a, v, key) {
    let lo = 0, hi = a.length - 1, r = -1;
    while (lo <= hi) {
      const m = (lo + hi) >> 1;
      const x = key ? key(a[m]) : a[m];
      if (x <= v) { r = m; lo = m + 1; } else hi = m - 1;
    }
    return r;
  }
  function nearestIndexOfTime(t) {
    const i = lastAtOrBefore(T, t);
    if (i < 0) return 0;
    if (i + 1 < N && t - T[i] > T[i + 1] - t) return i + 1;
    return i;
  }
  //@commonroad
  // A CommonRoad run (`frenetic commonroad --record`): the verdict's failures are its incidents,
  // each at the cycle of its time step.
  for (const f of (D.footer && Array.isArray(D.footer.failures) ? D.footer.failures : [])) {
    const e = nearestIndexOfTime(f.step * H.dt);
    D.incidents.push({ e, t: T[e], s: E.s[e], d: E.d[e], lane: E.lane[e], kind: f.kind,
                       value: num(f.obstacle) ? f.obstacle : null });
  }
  D.incidents.sort((a, b) => a.e - b.e);
  //@end
  const PALETTE = ["#1570ef", "#e04f16", "#12b76a", "#9e77ed", "#f79009", "#0e9384", "#dd2590",
                   "#475467", "#66c61c", "#6172f3"];

  const state = { k: 0, playing: false, zoom: 3.0, rate: 4, detail: -1, showCandidates: true,
                  simTime: T.length ? T[0] : 0, lastFrame: 0 };

  // The judgement of an incident (drive's judging, sim/incident_judge.h): the footer's
  // incident_log is in the same order as the exchanges' incidents. Null when not judged.
  function judgementOf(incident) {
    const log = D.footer && Array.isArray(D.footer.incident_log) ? D.footer.incident_log : [];
    const entry = log[D.incidents.indexOf(incident)];
    return entry && typeof entry.judgement === "object" && entry.judgement ? entry.judgement : null;
  }

  // ---------- summary header ----------
  function buildSummary() {
    const root = $("summary");
    const title = "frenetic report" + (H.scenario ? " \u00b7 " + H.scenario : "") +
        (H.planner ? " \u00b7 " + H.planner : "");
    document.title = title;
    root.append(el("h1", {}, title));
    root.append(el("div", { class: "sub" },
        `record ${D.source} \u00b7 map ${H.map || DASH} \u00b7 seed ${H.seed} \u00b7 ` +
        `${H.lanes} lanes of ${H.lane_width} m \u00b7 ${N} exchanges over ` +
        `${fmt(T[N - 1] - T[0], 1)} s \u00b7 ${D.generator}`));
    //@commonroad
    const verdict = !D.footer ? "no verdict (run cut short)"
        : (D.footer.solved ? `solved, goal at step ${D.footer.goal_step}` : "NOT solved") +
          ` (stopped by ${D.footer.stop_reason})`;
    root.append(el("div", { class: "sub" },
        `CommonRoad ${H.scenario}, planning problem ${H.problem} \u00b7 time step ${H.dt} s \u00b7 ` +
        `${H.prediction} predictions \u00b7 vehicle ${H.vehicle} \u00b7 ${verdict}`));
    for (const f of (D.footer && Array.isArray(D.footer.failures) ? D.footer.failures : [])) {
      root.append(el("div", { class: "warn" }, `${f.kind} at step ${f.step}: ${f.detail}`));
    }
    //@end
    const f = D.footer || {};
    const tiles = el("div", { class: "tiles", id: "summary-tiles" });
    function tile(key, value, bad) {
      tiles.append(el("div", { class: "tile" + (bad ? " bad" : "") },
                      el("div", { class: "k" }, key), el("div", { class: "v" }, value)));
    }
    // The spec's names (incidents_total, plan_ms_p50...) and the simulator's (incidents as a
    // number, incidents_by_kind, plan_ms {p50, p99, max}) are both understood.
    const byKind = typeof f.incidents === "object" && f.incidents ? f.incidents
                 : typeof f.incidents_by_kind === "object" && f.incidents_by_kind ? f.incidents_by_kind : null;
    const incidentsTotal = num(f.incidents_total) ? f.incidents_total
                         : num(f.incidents) ? f.incidents : D.incidents.length;
    const planMs = typeof f.plan_ms === "object" && f.plan_ms ? f.plan_ms : {};
    const p50 = num(f.plan_ms_p50) ? f.plan_ms_p50 : planMs.p50;
    const p99 = num(f.plan_ms_p99) ? f.plan_ms_p99 : planMs.p99;
    const pmax = num(f.plan_ms_max) ? f.plan_ms_max : planMs.max;
    const miles = num(f.distance_miles) ? f.distance_miles : f.miles;
    if (!D.footer) {
      tiles.append(el("div", { class: "tile bad" }, el("div", { class: "k" }, "footer"),
                      el("div", { class: "v" }, "none: run cut short")));
    }
    let distance = f.distance_m;
    if (!num(distance)) {  // no footer: the path length of the ego's positions
      distance = 0;
      for (let i = 1; i < N; ++i) distance += Math.hypot(E.x[i] - E.x[i - 1], E.y[i] - E.y[i - 1]);
    }
    tile("distance", `${fmt(distance, 0)} m / ${fmt(num(miles) ? miles : distance / 1609.344, 2)} mi`);
    tile("simulated time", `${fmt(num(f.sim_seconds) ? f.sim_seconds : T[N - 1] - T[0], 1)} s`);
    tile("average speed", `${fmt(f.avg_speed_mph, 1)} mph`);
    tile("incidents", String(incidentsTotal), incidentsTotal > 0);
    if (byKind) {
      for (const [kind, n] of Object.entries(byKind)) {
        if (n > 0) tile(kind, String(n), true);
      }
    }
    tile("miles to 1st incident", fmt(f.miles_to_first_incident, 2));
    //@commonroad
    // No simulator limits: the planner's speed cap, and no acceleration or jerk measures.
    tile("max speed", `${fmt(f.max_speed_mph, 1)} mph`, num(CAP) && f.max_speed_mph > CAP);
    //@else
    tile("max speed", `${fmt(f.max_speed_mph, 1)} mph`, f.max_speed_mph > 50);
    tile("max acc", `${fmt(f.max_acc, 2)} m/s\u00b2`, f.max_acc > 10);
    tile("max jerk", `${fmt(f.max_jerk, 2)} m/s\u00b3`, f.max_jerk > 10);
    //@end
    tile("lane changes", fmt(f.lane_changes, 0));
    tile("min gap", `${fmt(f.min_gap_m, 1)} m`);
    tile("min headway", `${fmt(f.min_headway_s, 2)} s`);
    tile("plan p50 / p99", `${fmt(p50, 2)} / ${fmt(p99, 2)} ms`);
    tile("plan max", `${fmt(pmax, 2)} ms`);
    if (num(f.plan_fallbacks)) tile("fallback cycles", String(f.plan_fallbacks), f.plan_fallbacks > 0);
    if (typeof f.stop_reason === "string") tile("stopped by", f.stop_reason);
    root.append(tiles);

    const inc = el("div", { id: "incidents" });
    if (D.incidents.length === 0) {
      inc.append(el("span", { class: "hint" }, "No incident."));
    } else {
      inc.append(el("span", {}, `${D.incidents.length} incident(s): `));
      for (const i of D.incidents.slice(0, 200)) {
        const j = judgementOf(i);
        inc.append(el("button", { type: "button", class: "incident",
                                  title: `s ${fmt(i.s, 1)} m, d ${fmt(i.d, 2)} m, value ${fmt(i.value)}` +
                                         (j ? `\n${j.summary}` : ""),
                                  onclick: () => { setCycle(i.e); showDetails(i.e); } },
                      `${i.kind} at ${fmt(i.t, 1)} s (lane ${i.lane})` +
                      (j ? ` \u00b7 ${j.verdict.replace("_", " ")}` : "")));
      }
      if (D.incidents.length > 200) inc.append(` \u2026 and ${D.incidents.length - 200} more`);
    }
    root.append(inc);

    const config = el("details", { id: "config" }, el("summary", {}, "configuration used"),
                      el("pre", {}, typeof H.config === "string" ? H.config
                                                                 : JSON.stringify(H.config, null, 2)));
    root.append(config);
    if (D.reading.skipped > 0) {
      const w = el("details", { class: "warn" },
                   el("summary", {}, `${D.reading.skipped} malformed line(s) skipped while reading`));
      const ul = el("ul");
      for (const m of D.reading.warnings) ul.append(el("li", {}, m));
      w.append(ul);
      root.append(w);
    }
  }

  // ---------- road geometry ----------
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
  const road = { surface: null, center: null, lanes: [], edge: null };
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
  //@commonroad
  // A CommonRoad road: each lane's borders as recorded (lanes may begin, end, widen and bend
  // apart); the leftmost lane's left border solid yellow, the rightmost's right border solid
  // white, every border dashed. Goal regions as outlines.
  const GOALS = [];
  if (Array.isArray(D.road) && D.road.length) {
    road.surface = new Path2D();
    road.center = new Path2D();
    road.edge = new Path2D();
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
    });
  }
  for (const g of (Array.isArray(D.goals) ? D.goals : [])) {
    if (g.x.length < 2) continue;
    const p = linePath(g.x, g.y);
    p.closePath();
    GOALS.push({ path: p, steps: g.steps });
  }
  //@end

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
      ctx.lineWidth = 1.5 * px * dpr;
      ctx.setLineDash([3, 6]);  // m: like road markings
      for (const p of road.lanes) ctx.stroke(p);
      ctx.setLineDash([]);
    }
    //@commonroad
    // Goal regions: filled more strongly inside their time window.
    for (const g of GOALS) {
      const step = T[k] / H.dt;
      const open = !g.steps || (step >= g.steps[0] - 1e-6 && step <= g.steps[1] + 1e-6);
      ctx.fillStyle = open ? "rgba(18,183,106,0.35)" : "rgba(18,183,106,0.12)";
      ctx.fill(g.path);
      ctx.strokeStyle = "#12b76a";
      ctx.lineWidth = 1.5 * px * dpr;
      ctx.stroke(g.path);
    }
    //@end
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
      //@commonroad
      // Each car of its recorded size.
      box(ctx, D.traffic.x[j], D.traffic.y[j], num(h) ? h * Math.PI / 180 : yaw,
          D.traffic.l && num(D.traffic.l[j]) ? D.traffic.l[j] : H.car_length,
          D.traffic.w && num(D.traffic.w[j]) ? D.traffic.w[j] : H.car_width);
      //@else
      box(ctx, D.traffic.x[j], D.traffic.y[j], num(h) ? h * Math.PI / 180 : yaw,
          H.car_length, H.car_width);
      //@end
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
  //@commonroad
  $("replay-legend").innerHTML +=
      '<span><i class="swatch" style="background:rgba(18,183,106,0.35);border:1px solid #12b76a"></i>' +
      'goal region (strong inside its time window)</span>';
  //@end

  // ---------- plots ----------
  const plots = [];
  function series(name, values, color, step) { return { name, values, color, step }; }
  function contribution(term) {
    const out = new Array(N);
    for (let i = 0; i < N; ++i) {
      const w = Array.isArray(term.weight) ? term.weight[i] : term.weight;
      const v = term.value[i];
      out[i] = num(w) && num(v) ? w * v : null;
    }
    return out;
  }
  function quantile(values, q) {
    const a = values.filter(num).sort((x, y) => x - y);
    if (!a.length) return NaN;
    return a[Math.min(a.length - 1, Math.floor(q * (a.length - 1)))];
  }
  function buildPlots() {
    const specs = [
      //@commonroad
      // The planner's speed cap; no simulator acceleration or jerk measures to plot.
      { id: "speed", title: "speed", unit: "mph", series: [series("speed", E.speed, "#1570ef")],
        limits: num(CAP) ? [[CAP, `${fmt(CAP, 1)} mph (planner's cap)`]] : [], lo: 0 },
      //@else
      { id: "speed", title: "speed", unit: "mph", series: [series("speed", E.speed, "#1570ef")],
        limits: [[50, "50 mph"]], lo: 0 },
      { id: "acc", title: "total acceleration (simulator)", unit: "m/s\u00b2",
        series: [series("acc", E.acc, "#e04f16")], limits: [[10, "10"]], lo: 0 },
      { id: "jerk", title: "jerk (simulator)", unit: "m/s\u00b3",
        series: [series("jerk", E.jerk, "#9e77ed")], limits: [[10, "10"]], lo: 0 },
      //@end
      { id: "lane", title: "lane (0 = left)", unit: "",
        series: [series("lane", E.lane.map((v) => v >= 0 ? v : null), "#0e9384", true),
                 series("winner's target", E.winner_lane.map((v) => v >= 0 ? v : null), "#f79009", true)],
        lo: -0.5, hi: H.lanes - 0.5, invert: true },
      { id: "gap", title: "gap to the car ahead", unit: "m", series: [series("gap", E.gap, "#475467")],
        lo: 0, robust: true },
      { id: "headway", title: "time headway", unit: "s",
        series: [series("headway", E.headway, "#dd2590")], lo: 0, robust: true },
      { id: "ms", title: "planning time per cycle", unit: "ms",
        series: [series("ms", E.ms, "#66c61c")], lo: 0, robust: true },
      { id: "cost", title: "winner's cost per term (weight \u00d7 value)", unit: "",
        series: D.terms.map((t, i) => series(t.name, contribution(t), PALETTE[i % PALETTE.length])),
        lo: 0, robust: true },
    ];
    if (D.rejections.some((r) => r.count.some((n) => n > 0))) {
      specs.push({ id: "rejections", title: "rejected candidates per cycle, by reason", unit: "",
                   series: D.rejections.map((r, i) => series(r.name, r.count, PALETTE[(i + 3) % PALETTE.length])),
                   lo: 0 });
    }
    const root = $("plots");
    for (const spec of specs) {
      if (!spec.series.length || !spec.series.some((s) => s.values.some(num))) continue;
      const c = el("canvas", { id: "plot-" + spec.id, "data-cursor-x": "" });
      const readout = el("span", { class: "readout" });
      const legend = el("span", {});
      if (spec.series.length > 1) {
        for (const s of spec.series) {
          legend.append(el("span", { style: `margin-left:8px;color:${s.color}` }, "\u25a0 " + s.name));
        }
      }
      const box = el("div", { class: "plot", id: "plot-box-" + spec.id },
                     el("div", { class: "title" }, el("span", {}, el("b", {}, spec.title),
                                                       spec.unit ? ` (${spec.unit})` : "", legend),
                        readout),
                     c);
      root.append(box);
      const plot = { spec, canvas: c, readout, ctx: c.getContext("2d"), layer: null };
      let hi = spec.hi;
      if (hi === undefined) {
        hi = -Infinity;
        for (const s of spec.series) {
          const top = spec.robust ? quantile(s.values, 0.995) * 1.15 : quantile(s.values, 1);
          if (num(top)) hi = Math.max(hi, top);
        }
        for (const [v] of spec.limits || []) hi = Math.max(hi, v * 1.15);
        if (!(hi > spec.lo)) hi = spec.lo + 1;
      }
      plot.lo = spec.lo; plot.hi = hi;
      c.addEventListener("click", (ev) => {
        const r = c.getBoundingClientRect();
        const k = nearestIndexOfTime(plotTime(plot, (ev.clientX - r.left) * dpr));
        setCycle(k);
        showDetails(k);
      });
      plots.push(plot);
    }
  }
  const PAD_L = 44, PAD_R = 8, PAD_T = 6, PAD_B = 16;
  function plotX(plot, t) {
    const w = plot.canvas.width - (PAD_L + PAD_R) * dpr;
    const span = T[N - 1] - T[0] || 1;
    return PAD_L * dpr + (t - T[0]) / span * w;
  }
  function plotTime(plot, x) {
    const w = plot.canvas.width - (PAD_L + PAD_R) * dpr;
    return T[0] + (x - PAD_L * dpr) / w * (T[N - 1] - T[0]);
  }
  function plotY(plot, v) {
    const h = plot.canvas.height - (PAD_T + PAD_B) * dpr;
    let u = (v - plot.lo) / (plot.hi - plot.lo);
    if (plot.spec.invert) u = 1 - u;
    return PAD_T * dpr + (1 - clamp(u, -0.02, 1.02)) * h;
  }
  // The static part of a plot (axes, series, limits, incidents), drawn once per size: moving the
  // cursor then costs one drawImage per plot, whatever the run's length.
  function renderLayer(plot) {
    const c = plot.canvas;
    c.width = Math.max(1, Math.round(c.clientWidth * dpr));
    c.height = Math.max(1, Math.round(c.clientHeight * dpr));
    const layer = document.createElement("canvas");
    layer.width = c.width; layer.height = c.height;
    const g = layer.getContext("2d");
    g.fillStyle = "#fff";
    g.fillRect(0, 0, c.width, c.height);
    g.font = `${10 * dpr}px system-ui, sans-serif`;
    g.fillStyle = "#667085";
    g.strokeStyle = "#eaecf0";
    g.lineWidth = 1;
    // Horizontal grid with labels.
    const ticks = plot.spec.id === "lane" ? Array.from({ length: H.lanes }, (_, i) => i)
                                          : [0, 0.25, 0.5, 0.75, 1].map((u) => plot.lo + u * (plot.hi - plot.lo));
    g.textAlign = "right";
    g.textBaseline = "middle";
    for (const v of ticks) {
      const y = plotY(plot, v);
      g.beginPath(); g.moveTo(PAD_L * dpr, y); g.lineTo(c.width - PAD_R * dpr, y); g.stroke();
      g.fillText(fmt(v), (PAD_L - 4) * dpr, y);
    }
    // Time labels.
    g.textAlign = "center";
    g.textBaseline = "bottom";
    const span = T[N - 1] - T[0];
    const step = niceStep(span / 8);
    for (let t = Math.ceil(T[0] / step) * step; t <= T[N - 1]; t += step) {
      g.fillText(fmt(t, step < 1 ? 1 : 0) + " s", plotX(plot, t), c.height);
    }
    // Limit lines.
    g.setLineDash([5 * dpr, 4 * dpr]);
    g.strokeStyle = "#f04438";
    for (const [v, label] of plot.spec.limits || []) {
      const y = plotY(plot, v);
      g.beginPath(); g.moveTo(PAD_L * dpr, y); g.lineTo(c.width - PAD_R * dpr, y); g.stroke();
      g.fillStyle = "#f04438";
      g.textAlign = "left";
      g.fillText(label, (PAD_L + 2) * dpr, y - 1);
    }
    g.setLineDash([]);
    // Series: one vertical min-max segment per device pixel column, so 25,000 points draw as
    // fast as 500 and no spike is lost.
    const x0 = PAD_L * dpr, cols = Math.max(1, Math.floor(c.width - (PAD_L + PAD_R) * dpr));
    for (const s of plot.spec.series) {
      const mins = new Float64Array(cols + 1).fill(NaN), maxs = new Float64Array(cols + 1).fill(NaN);
      const firsts = new Float64Array(cols + 1).fill(NaN), lasts = new Float64Array(cols + 1).fill(NaN);
      const breaks = new Uint8Array(cols + 1);  // a missing value (null) lies before this column
      let missing = false;
      for (let i = 0; i < N; ++i) {
        const v = s.values[i];
        if (!num(v)) { missing = true; continue; }
        const col = clamp(Math.round(plotX(plot, T[i]) - x0), 0, cols);
        if (isNaN(mins[col])) { mins[col] = maxs[col] = firsts[col] = v; if (missing) breaks[col] = 1; }
        missing = false;
        mins[col] = Math.min(mins[col], v);
        maxs[col] = Math.max(maxs[col], v);
        lasts[col] = v;
      }
      g.strokeStyle = s.color;
      g.lineWidth = 1.3 * dpr;
      g.beginPath();
      let prev = -1;
      for (let col = 0; col <= cols; ++col) {
        if (isNaN(mins[col])) continue;
        const x = x0 + col;
        if (prev >= 0 && !breaks[col]) {
          // Sparse data spans several columns per sample: join the samples.
          if (s.step) g.lineTo(x, plotY(plot, lasts[prev]));
          g.lineTo(x, plotY(plot, firsts[col]));
        } else {
          g.moveTo(x, plotY(plot, firsts[col]));
        }
        g.lineTo(x, plotY(plot, mins[col]));
        g.lineTo(x, plotY(plot, maxs[col]));
        g.lineTo(x, plotY(plot, lasts[col]));
        prev = col;
      }
      g.stroke();
    }
    // Incidents: a red line and a marker on every plot.
    g.strokeStyle = "rgba(217,45,32,0.8)";
    g.fillStyle = "#d92d20";
    g.lineWidth = 1.5 * dpr;
    for (const inc of D.incidents) {
      const x = plotX(plot, inc.t);
      g.beginPath(); g.moveTo(x, PAD_T * dpr); g.lineTo(x, c.height - PAD_B * dpr); g.stroke();
      g.beginPath();
      g.moveTo(x - 4 * dpr, 0); g.lineTo(x + 4 * dpr, 0); g.lineTo(x, 7 * dpr); g.closePath();
      g.fill();
    }
    plot.layer = layer;
    plot.canvas.setAttribute("data-incidents", String(D.incidents.length));
  }
  function niceStep(raw) {
    const p = Math.pow(10, Math.floor(Math.log10(Math.max(raw, 1e-9))));
    for (const m of [1, 2, 5, 10]) if (m * p >= raw) return m * p;
    return 10 * p;
  }
  function drawPlot(plot) {
    if (!plot.layer) renderLayer(plot);
    const g = plot.ctx, c = plot.canvas, k = state.k;
    g.drawImage(plot.layer, 0, 0);
    const x = Math.round(plotX(plot, T[k])) + 0.5;
    g.strokeStyle = "#101828";
    g.lineWidth = 1.5 * dpr;
    g.beginPath(); g.moveTo(x, 0); g.lineTo(x, c.height - PAD_B * dpr); g.stroke();
    if (state.detail >= 0 && state.detail !== k) {
      const xd = Math.round(plotX(plot, T[state.detail])) + 0.5;
      g.strokeStyle = "rgba(21,112,239,0.6)";
      g.setLineDash([3 * dpr, 3 * dpr]);
      g.beginPath(); g.moveTo(xd, 0); g.lineTo(xd, c.height - PAD_B * dpr); g.stroke();
      g.setLineDash([]);
    }
    c.setAttribute("data-cursor-x", String(x));
    plot.readout.textContent = plot.spec.series.map((s) =>
        (plot.spec.series.length > 1 ? s.name + " " : "") + fmt(s.values[k])).join("  ");
  }

  // ---------- details of one cycle ----------
  function showDetails(k) {
    state.detail = k;
    const root = $("details");
    root.textContent = "";
    root.append(el("h2", {}, `Cycle ${E.i[k]} at t = ${fmt(T[k], 2)} s`));
    const st = E.status[k] >= 0 ? D.status_names[E.status[k]] : DASH;
    root.append(el("div", { class: "kv" },
        el("span", {}, "status ", el("b", {}, st)),
        el("span", {}, "generated ", el("b", {}, E.generated[k])),
        el("span", {}, "scored ", el("b", {}, E.scored[k])),
        el("span", {}, "checked ", el("b", {}, E.checked[k])),
        el("span", {}, "feasible ", el("b", {}, E.feasible[k])),
        el("span", {}, "plan ", el("b", {}, fmt(E.ms[k], 2) + " ms")),
        el("span", {}, "winner lane ", el("b", {}, E.winner_lane[k])),
        el("span", {}, "refine ", el("b", {}, `${E.refine_iterations[k]} it, ${fmt(E.refine_before[k])} \u2192 ${fmt(E.refine_after[k])}`))));
    const incs = D.incidents.filter((i) => i.e === k);
    for (const i of incs) {
      root.append(el("div", { class: "warn" }, `incident: ${i.kind} (value ${fmt(i.value)}) at s ${fmt(i.s, 1)} m, lane ${i.lane}`));
      const j = judgementOf(i);
      if (j) {
        root.append(el("div", { class: "warn" },
                       `judged: ${j.summary}` + (j.escape ? `; escape: ${j.escape}` : "")));
      }
    }
    // Rejections by reason.
    root.append(el("h3", {}, "Rejections by reason"));
    const rt = el("table", { id: "rejection-table" });
    rt.append(el("tr", {}, ...D.rejections.map((r) => el("th", {}, r.name)), el("th", {}, "all")));
    let all = 0;
    const cells = D.rejections.map((r) => { all += r.count[k]; return el("td", { class: r.count[k] ? "" : "zero" }, r.count[k]); });
    rt.append(el("tr", {}, ...cells, el("td", {}, all)));
    root.append(rt);

    // Candidates with their terms: the winner and the next best.
    // Candidates are kept for a subset of cycles: take the nearest kept one, before or after.
    const j = lastAtOrBefore(CAND, k, (c) => c.e);
    let cand = j >= 0 ? CAND[j] : null;
    if (j + 1 < CAND.length && (!cand || T[CAND[j + 1].e] - T[k] < T[k] - T[cand.e])) cand = CAND[j + 1];
    const table = el("table", { id: "cost-table" });
    if (cand) {
      root.append(el("h3", {}, cand.e === k ? "Candidates: the winner and the next best"
          : `Candidates of the nearest kept cycle ${E.i[cand.e]} (${fmt(Math.abs(T[k] - T[cand.e]), 2)} s ` +
            `${cand.e < k ? "earlier" : "later"})`));
      const rows = cand.c.map((c, i) => ({ c, i }));
      const winner = rows.find((r) => r.c[4] & 2);
      const shown = (winner ? [winner] : []).concat(rows.filter((r) => r !== winner).slice(0, winner ? 4 : 5));
      const head = el("tr", {}, el("th", {}, "term"));
      const sub = el("tr", {}, el("th", {}, ""));
      for (const r of shown) {
        const c = r.c;
        const cls = c[4] & 2 ? "win" : c[5] ? "rej" : "";
        const what = c[4] & 2 ? "winner" : c[5] ? "rejected: " + c[5] : c[4] & 1 ? "passed" : "not checked";
        head.append(el("th", { colspan: 3, class: cls },
                       `#${r.i + 1} lane ${c[0]}, ${fmt(c[1], 1)} m/s, ${fmt(c[2], 1)} s \u2014 ${what}`));
        sub.append(el("th", { class: cls }, "weight"), el("th", { class: cls }, "value"),
                   el("th", { class: cls }, "w\u00d7v"));
      }
      table.append(head, sub);
      const termIds = [];
      for (const r of shown) for (let j = 0; j < r.c[8].length; j += 3) if (!termIds.includes(r.c[8][j])) termIds.push(r.c[8][j]);
      for (const ti of termIds) {
        const tr = el("tr", {}, el("td", {}, D.terms[ti] ? D.terms[ti].name : "#" + ti));
        for (const r of shown) {
          const cls = r.c[4] & 2 ? "win" : r.c[5] ? "rej" : "";
          let w = null, v = null;
          for (let j = 0; j < r.c[8].length; j += 3) if (r.c[8][j] === ti) { w = r.c[8][j + 1]; v = r.c[8][j + 2]; }
          tr.append(el("td", { class: cls }, fmt(w)), el("td", { class: cls }, fmt(v)),
                    el("td", { class: cls }, num(w) && num(v) ? fmt(w * v) : DASH));
        }
        table.append(tr);
      }
      const total = el("tr", {}, el("th", {}, "total"));
      for (const r of shown) total.append(el("th", { colspan: 3, class: r.c[4] & 2 ? "win" : "" }, fmt(r.c[3])));
      table.append(total);
      root.append(table);
      root.append(el("p", { class: "hint" }, `${cand.c.length} of ${cand.listed} recorded candidates kept for this cycle.`));
    } else {
      // No candidates kept near this cycle: the winner's terms are recorded for every cycle.
      root.append(el("h3", {}, "Winner's cost terms (no candidates kept for this cycle)"));
      table.append(el("tr", {}, el("th", {}, "term"), el("th", {}, "weight"), el("th", {}, "value"), el("th", {}, "w\u00d7v")));
      for (const t of D.terms) {
        const w = Array.isArray(t.weight) ? t.weight[k] : t.weight, v = t.value[k];
        table.append(el("tr", {}, el("td", {}, t.name), el("td", {}, fmt(w)), el("td", {}, fmt(v)),
                        el("td", {}, num(w) && num(v) ? fmt(w * v) : DASH)));
      }
      table.append(el("tr", {}, el("th", {}, "total"), el("th", { colspan: 3 }, fmt(E.cost[k]))));
      root.append(table);
    }
    for (const p of plots) drawPlot(p);
  }

  // ---------- time control ----------
  const slider = $("slider");
  slider.max = String(Math.max(0, N - 1));
  function setCycle(k) {
    state.k = clamp(k | 0, 0, N - 1);
    state.simTime = T[state.k];
    slider.value = String(state.k);
    redraw();
  }
  function redraw() {
    $("clock").textContent = `t ${fmt(T[state.k], 2)} s \u00b7 ${state.k + 1} / ${N}`;
    drawReplay();
    for (const p of plots) drawPlot(p);
  }
  function frame(now) {
    if (!state.playing) return;
    const dt = state.lastFrame ? Math.min(0.1, (now - state.lastFrame) / 1000) : 0;
    state.lastFrame = now;
    state.simTime += dt * state.rate;
    let k = state.k;
    while (k + 1 < N && T[k + 1] <= state.simTime) ++k;
    if (k !== state.k) {
      state.k = k;
      slider.value = String(k);
      redraw();
    }
    if (k >= N - 1) { setPlaying(false); return; }
    requestAnimationFrame(frame);
  }
  function setPlaying(on) {
    state.playing = on;
    $("play").textContent = on ? "Pause" : "Play";
    if (on) {
      if (state.k >= N - 1) setCycle(0);
      state.simTime = T[state.k];
      state.lastFrame = 0;
      requestAnimationFrame(frame);
    }
  }
  function zoomBy(f) { state.zoom = clamp(state.zoom * f, 0.05, 40); drawReplay(); }

  buildSummary();
  buildPlots();
  $("play").addEventListener("click", () => setPlaying(!state.playing));
  slider.addEventListener("input", () => { setPlaying(false); setCycle(Number(slider.value)); });
  $("rate").addEventListener("change", (e) => { state.rate = Number(e.target.value); });
  $("zoom-in").addEventListener("click", () => zoomBy(1.5));
  $("zoom-out").addEventListener("click", () => zoomBy(1 / 1.5));
  $("prev").addEventListener("click", () => setCycle(state.k - 1));
  $("next").addEventListener("click", () => setCycle(state.k + 1));
  $("details-button").addEventListener("click", () => showDetails(state.k));
  $("show-candidates").addEventListener("change", (e) => { state.showCandidates = e.target.checked; drawReplay(); });
  canvas.addEventListener("wheel", (e) => { e.preventDefault(); zoomBy(e.deltaY < 0 ? 1.2 : 1 / 1.2); },
                          { passive: false });
  document.addEventListener("keydown", (e) => {
    if (e.target && (e.target.tagName === "INPUT" || e.target.tagName === "SELECT")) return;
    if (e.key === " ") { e.preventDefault(); setPlaying(!state.playing); }
    else if (e.key === "ArrowLeft") setCycle(state.k - 1);
    else if (e.key === "ArrowRight") setCycle(state.k + 1);
    else if (e.key === "+" || e.key === "=") zoomBy(1.5);
    else if (e.key === "-") zoomBy(1 / 1.5);
  });
  let resizeTimer = 0;
  window.addEventListener("resize", () => {
    clearTimeout(resizeTimer);
    resizeTimer = setTimeout(() => {
      resizeReplay();
      for (const p of plots) p.layer = null;
      redraw();
    }, 100);
  });
  resizeReplay();
  setCycle(0);
  // For tests and the console: the page's state and controls.
  window.freneticReport = { data: D, state, setCycle, showDetails, ready: true };
  document.body.setAttribute("data-ready", "1");
})();
