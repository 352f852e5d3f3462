// The frenetic report's script, part 2 of 7 (see core.js): the summary header (title, the
// run's verdict, tiles of the footer's figures, the incidents as buttons, the configuration).
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
  if (COMMONROAD) {
    const verdict = !D.footer ? "no verdict (run cut short)"
        : (D.footer.solved ? `solved, goal at step ${D.footer.goal_step}` : "NOT solved") +
          ` (stopped by ${D.footer.stop_reason})`;
    root.append(el("div", { class: "sub" },
        `CommonRoad ${H.scenario}, planning problem ${H.problem} \u00b7 time step ${H.dt} s \u00b7 ` +
        `${H.prediction} predictions \u00b7 vehicle ${H.vehicle} \u00b7 ${verdict}`));
    for (const f of (D.footer && Array.isArray(D.footer.failures) ? D.footer.failures : [])) {
      root.append(el("div", { class: "warn" }, `${f.kind} at step ${f.step}: ${f.detail}`));
    }
  }
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
  if (COMMONROAD) {
    // No simulator limits: the planner's speed cap, and no acceleration or jerk measures.
    tile("max speed", `${fmt(f.max_speed_mph, 1)} mph`, num(CAP) && f.max_speed_mph > CAP);
  } else {
    tile("max speed", `${fmt(f.max_speed_mph, 1)} mph`, f.max_speed_mph > 50);
    tile("max acc", `${fmt(f.max_acc, 2)} m/s\u00b2`, f.max_acc > 10);
    tile("max jerk", `${fmt(f.max_jerk, 2)} m/s\u00b3`, f.max_jerk > 10);
  }
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
