// The frenetic report's script, part 6 of 7 (see core.js): the details of one cycle (its
// planning figures, incidents, rejections by reason, and the cost table of its candidates, or
// of the nearest kept cycle's).

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
