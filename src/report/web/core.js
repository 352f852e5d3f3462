// The frenetic report's script, part 1 of 7 (report.cmake joins the parts, in its order, into
// one function scope): the data embedded by `frenetic report` (format "frenetic-report" v1,
// written by src/report/page.cc), the one switch between a drive's page and a CommonRoad run's,
// small helpers and the page's state. The views (summary.js, road.js, replay.js, plots.js,
// details.js) draw with plain DOM and canvas code (no library, works offline); main.js wires the
// controls and starts the page.
const D = JSON.parse(document.getElementById("frenetic-data").textContent);
const E = D.ex;
const N = D.n;
const H = D.header;
const T = E.t;
const DASH = "\u2013";
// A CommonRoad run (`frenetic commonroad --record`): its road's lanes, goal regions, cars of
// their own sizes, its verdict, and the planner's speed cap in place of the simulator's limits.
// The only switch between the two kinds of page.
const COMMONROAD = H.world === "commonroad";
const CAP = ((H.config || {}).limits || {}).max_speed_mph;  // mph: the planner's speed cap

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
if (COMMONROAD) {
  // The verdict's failures are the run's incidents, each at the cycle of its time step.
  for (const f of (D.footer && Array.isArray(D.footer.failures) ? D.footer.failures : [])) {
    const e = nearestIndexOfTime(f.step * H.dt);
    D.incidents.push({ e, t: T[e], s: E.s[e], d: E.d[e], lane: E.lane[e], kind: f.kind,
                       value: num(f.obstacle) ? f.obstacle : null });
  }
  D.incidents.sort((a, b) => a.e - b.e);
}
const PALETTE = ["#1570ef", "#e04f16", "#12b76a", "#9e77ed", "#f79009", "#0e9384", "#dd2590",
                 "#475467", "#66c61c", "#6172f3"];

const state = { k: 0, playing: false, zoom: 3.0, rate: 4, detail: -1, showCandidates: true,
                simTime: T.length ? T[0] : 0, lastFrame: 0 };

// The judgement of an incident (drive's judging, eval/incident_judge.h): the footer's
// incident_log is in the same order as the exchanges' incidents. Null when not judged.
function judgementOf(incident) {
  const log = D.footer && Array.isArray(D.footer.incident_log) ? D.footer.incident_log : [];
  const entry = log[D.incidents.indexOf(incident)];
  return entry && typeof entry.judgement === "object" && entry.judgement ? entry.judgement : null;
}
