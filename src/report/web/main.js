// The frenetic report's script, part 7 of 7 (see core.js): time control (slider, play, keys),
// the controls' wiring, and the start of the page.

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
window.freneticReport = { data: D, state, setCycle, showDetails, commonroad: COMMONROAD,
                          ready: true };
document.body.setAttribute("data-ready", "1");
