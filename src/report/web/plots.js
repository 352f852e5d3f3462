// The frenetic report's script, part 5 of 7 (see core.js): plots over time, one per measure,
// each with a cursor at the current cycle and a mark at every incident; a click on one selects
// the cycle under the mouse.

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
    ...(COMMONROAD ? [
      // The planner's speed cap; no simulator acceleration or jerk measures to plot.
      { id: "speed", title: "speed", unit: "mph", series: [series("speed", E.speed, "#1570ef")],
        limits: num(CAP) ? [[CAP, `${fmt(CAP, 1)} mph (planner's cap)`]] : [], lo: 0 },
    ] : [
      { id: "speed", title: "speed", unit: "mph", series: [series("speed", E.speed, "#1570ef")],
        limits: [[50, "50 mph"]], lo: 0 },
      { id: "acc", title: "total acceleration (simulator)", unit: "m/s\u00b2",
        series: [series("acc", E.acc, "#e04f16")], limits: [[10, "10"]], lo: 0 },
      { id: "jerk", title: "jerk (simulator)", unit: "m/s\u00b3",
        series: [series("jerk", E.jerk, "#9e77ed")], limits: [[10, "10"]], lo: 0 },
    ]),
    { id: "lane", title: "lane (0 = left)", unit: "",
      series: [series("lane", E.lane.map((v) => v >= 0 ? v : null), "#0e9384", true),
               series("winner's target", E.winner_lane.map((v) => v >= 0 ? v : null), "#f79009", true)],
      lo: -0.5, hi: H.lanes - 0.5, invert: true, integer: true },
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
                 lo: 0, integer: true });
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
      // Up to the next round value, which the top grid line then labels.
      plot.step = tickStep(spec.lo, hi, spec.integer);
      hi = Math.ceil(hi / plot.step - 1e-9) * plot.step;
    } else {
      plot.step = tickStep(spec.lo, hi, spec.integer);
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
  // Horizontal grid with labels, at round values.
  const digits = stepDigits(plot.step);
  const labels = [];
  g.textAlign = "right";
  g.textBaseline = "middle";
  for (const v of ticks(plot.lo, plot.hi, plot.step)) {
    const y = plotY(plot, v);
    g.beginPath(); g.moveTo(PAD_L * dpr, y); g.lineTo(c.width - PAD_R * dpr, y); g.stroke();
    labels.push(fmt(v, digits));
    g.fillText(labels[labels.length - 1], (PAD_L - 4) * dpr, y);
  }
  c.setAttribute("data-ticks", labels.join(" "));  // for tests
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
// The smallest round step (1, 2 or 5 times a power of ten) of at least `raw`.
function niceStep(raw) {
  const p = Math.pow(10, Math.floor(Math.log10(Math.max(raw, 1e-9))));
  for (const m of [1, 2, 5, 10]) if (m * p >= raw) return m * p;
  return 10 * p;
}
// The round step that cuts [lo, hi] into at most 5 intervals (at least 1 for counts and lanes).
function tickStep(lo, hi, integer) {
  const step = niceStep((hi - lo) / 5);
  return integer ? Math.max(1, step) : step;
}
// The multiples of `step` in [lo, hi].
function ticks(lo, hi, step) {
  const out = [];
  for (let i = Math.ceil(lo / step - 1e-9); i * step <= hi + step * 1e-9; ++i) out.push(i * step);
  return out;
}
// Digits after the point that a multiple of `step` needs.
function stepDigits(step) { return Math.max(0, Math.ceil(-Math.log10(step) - 1e-9)); }
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
      (plot.spec.series.length > 1 ? s.name + " " : "") +
      fmt(s.values[k], plot.spec.integer ? 0 : undefined)).join("  ");
}
