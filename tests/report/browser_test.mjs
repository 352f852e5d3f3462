// Browser test of the page written by `frenetic report`: Debian's headless Chromium, driven by
// playwright-core, opens reports of synthetic drives (written by frenetic_report_fixture) and
// checks what a user sees. Exit 0 pass, 1 fail, 77 skip (no chromium or no node_modules: run
// scripts/report-test-deps.sh).
//   node tests/report/browser_test.mjs --fixture BIN --out DIR [--large N]
import { execFileSync } from "node:child_process";
import { existsSync, mkdirSync, mkdtempSync, rmSync, statSync } from "node:fs";
import { createRequire } from "node:module";
import os from "node:os";
import path from "node:path";
import { pathToFileURL } from "node:url";

const SKIP = 77;
const args = Object.fromEntries(
  process.argv.slice(2).reduce((pairs, a, i, all) => (a.startsWith("--") ? [...pairs, [a.slice(2), all[i + 1]]] : pairs), []));
if (!args.fixture || !args.out) {
  console.error("usage: browser_test.mjs --fixture BIN --out DIR [--large N]");
  process.exit(2);
}
const chromiumPath = process.env.FRENETIC_CHROMIUM || "/usr/bin/chromium";
if (!existsSync(chromiumPath)) {
  console.log(`SKIP: ${chromiumPath} not found (scripts/report-test-deps.sh installs it)`);
  process.exit(SKIP);
}
let chromium;
try {
  ({ chromium } = createRequire(import.meta.url)("playwright-core"));
} catch {
  console.log("SKIP: tests/report/node_modules/playwright-core missing (scripts/report-test-deps.sh)");
  process.exit(SKIP);
}

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
  if (!ok) failures += 1;
}

mkdirSync(args.out, { recursive: true });
const fixtureArgs = [args.out, ...(args.large ? ["--large", args.large] : [])];
execFileSync(args.fixture, fixtureArgs, { stdio: "inherit" });

const userDataDir = mkdtempSync(path.join(os.tmpdir(), "frenetic-report-chromium-"));
const context = await chromium.launchPersistentContext(userDataDir, {
  executablePath: chromiumPath,
  headless: true,
  viewport: { width: 1400, height: 1000 },
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
// The page must be self-contained: any request other than the file itself fails the test.
const outside = [];
await context.route("**/*", (route) => {
  const url = route.request().url();
  if (url.startsWith("file:")) return route.continue();
  outside.push(url);
  return route.abort();
});

async function open(name) {
  const page = await context.newPage();
  const errors = [];
  page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
  page.on("pageerror", (e) => errors.push(String(e)));
  const file = path.join(args.out, name);
  const t0 = Date.now();
  await page.goto(pathToFileURL(file).href);
  await page.waitForSelector("body[data-ready='1']", { timeout: 30000 });
  const ms = Date.now() - t0;
  console.log(`     ${name}: ${(statSync(file).size / 1e6).toFixed(2)} MB, ready in ${ms} ms`);
  return { page, errors };
}

// Pixels of the replay canvas that differ from its grass background.
async function drawnPixels(page) {
  return page.evaluate(() => {
    const c = document.getElementById("replay");
    const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - 0x3d) + Math.abs(d[i + 1] - 0x7a) + Math.abs(d[i + 2] - 0x3a) > 30) n += 1;
    }
    return { n, total: d.length / 4 };
  });
}

// For each plot, the longest vertical run of incident-red pixels at each incident's time.
async function incidentMarks(page) {
  return page.evaluate(() => {
    const R = window.freneticReport.data;
    const t = R.ex.t, span = t[t.length - 1] - t[0];
    const out = {};
    for (const c of document.querySelectorAll("#plots canvas")) {
      const g = c.getContext("2d");
      const dpr = window.devicePixelRatio || 1;
      let best = 0;
      for (const inc of R.incidents) {
        const x = Math.round(44 * dpr + (inc.t - t[0]) / span * (c.width - 52 * dpr));
        const d = g.getImageData(x - 1, 0, 3, c.height).data;
        let run = 0;
        for (let y = 0; y < c.height; ++y) {
          let red = false;
          for (let dx = 0; dx < 3; ++dx) {
            const i = (y * 3 + dx) * 4;
            red = red || (d[i] > 180 && d[i + 1] < 110 && d[i + 2] < 100);
          }
          run = red ? run + 1 : 0;
          best = Math.max(best, run);
        }
      }
      out[c.id] = best / c.height;
    }
    return out;
  });
}

// The checks every page passes, a drive's or a CommonRoad run's (one template, one path here);
// `kind` holds what differs: the plots and tiles of the run's world, its incidents.
async function checkPage(name, kind) {
  const { page, errors } = await open(name);
  check((await page.evaluate(() => window.freneticReport.commonroad)) === kind.commonroad,
        `${name}: the page takes the run for ${kind.commonroad ? "a CommonRoad run" : "a drive"}`);
  const pixels = await drawnPixels(page);
  check(pixels.n > pixels.total * 0.02, `${name}: replay canvas has drawn (${pixels.n} of ${pixels.total} pixels not background)`);
  const plotIds = await page.$$eval("#plots canvas", (cs) => cs.map((c) => c.id));
  check(kind.plots.every((id) => plotIds.includes(id)) && !kind.noPlots.some((id) => plotIds.includes(id)),
        `${name}: plots present: ${plotIds.join(", ")}`);
  // Grid lines at round values (1, 2 or 5 times a power of ten, and their multiples).
  const ticks = Object.fromEntries(await page.$$eval("#plots canvas",
                                                      (cs) => cs.map((c) => [c.id, c.getAttribute("data-ticks")])));
  const round = (labels) => {
    const v = labels.split(" ").map(Number), step = v[1] - v[0];
    const m = step / 10 ** Math.floor(Math.log10(step) + 1e-9);
    return v.length >= 2 && [1, 2, 5].some((x) => Math.abs(m - x) < 1e-6) &&
           v.every((x, i) => Math.abs(x / step - Math.round(x / step)) < 1e-6 && Math.abs(x - v[0] - i * step) < step * 1e-6);
  };
  check(Object.values(ticks).every(round), `${name}: every plot's grid at round values (${JSON.stringify(ticks)})`);
  for (const [id, labels] of Object.entries(kind.ticks)) {
    check(ticks[id] === labels, `${name}: ${id} reads ${labels} (${ticks[id]})`);
  }
  const tiles = await page.$$eval(".tile", (ts) => ts.map((t) => t.textContent));
  check(kind.tiles.every((k) => tiles.some((t) => t.startsWith(k))) &&
        !kind.noTiles.some((k) => tiles.some((t) => t.startsWith(k))), `${name}: the tiles of its world`);
  const cursor = () => page.$$eval("#plots canvas", (cs) => cs.map((c) => Number(c.getAttribute("data-cursor-x"))));
  const before = await cursor();
  const frameBefore = await page.$eval("#replay", (c) => c.toDataURL());
  const n = await page.evaluate(() => window.freneticReport.data.n);
  await page.locator("#slider").fill(String(Math.floor(n / 2)));
  const after = await cursor();
  check(after.every((x, i) => x > before[i] + 50), `${name}: slider moves every plot's cursor (${before[0]} -> ${after[0]})`);
  check((await page.$eval("#replay", (c) => c.toDataURL())) !== frameBefore, `${name}: slider redraws the replay`);
  check((await page.textContent("#clock")).includes(`${Math.floor(n / 2) + 1} / ${n}`), `${name}: clock follows the slider`);
  // Zoom changes the replay.
  const frameZoom = await page.$eval("#replay", (c) => c.toDataURL());
  await page.click("#zoom-out");
  check((await page.$eval("#replay", (c) => c.toDataURL())) !== frameZoom, `${name}: zoom button redraws the replay`);
  // Click a cycle on the speed plot: its cost table appears.
  const box = await page.locator("#plot-speed").boundingBox();
  await page.mouse.click(box.x + box.width * 0.75, box.y + box.height / 2);
  const rows = await page.$$eval("#cost-table tr", (trs) => trs.map((tr) => tr.textContent));
  check(rows.length >= 6, `${name}: clicking the plot shows a cost table (${rows.length} rows)`);
  check(rows.some((r) => r.includes("winner")) && rows.some((r) => r.startsWith("lane_change")),
        `${name}: the table shows the winner and the cost terms`);
  check((await page.textContent("#details h2")).includes("Cycle"), `${name}: the details name the cycle`);
  const k = await page.evaluate(() => window.freneticReport.state.k);
  check(Math.abs(k - Math.floor(n * 0.75)) <= n * 0.03, `${name}: the click selects the cycle under the mouse (${k})`);
  check((await page.$$("#rejection-table td")).length >= 5, `${name}: rejection counts by reason`);
  // The details button works too, on the current cycle.
  await page.locator("#slider").fill("8");
  await page.click("#details-button");
  check((await page.textContent("#details h2")).includes("Cycle 8 "), `${name}: details button shows the current cycle`);
  check((await page.textContent("#details")).includes("rejected: "), `${name}: cycle 8's rejected best candidate is listed with its reason`);
  // Play advances time.
  await page.locator("#slider").fill("0");
  await page.click("#play");
  await page.waitForFunction(() => window.freneticReport.state.k > 5, null, { timeout: 10000 });
  await page.click("#play");
  check(true, `${name}: play advances the replay`);
  await page.locator("#slider").fill("120");
  await page.screenshot({ path: path.join(args.out, name.replace(".html", ".png")), fullPage: true });
  const incidentText = (await page.textContent("#incidents")).trim();
  check(incidentText.includes(kind.incidents), `${name}: header lists its incidents (${incidentText})`);
  for (const line of kind.summary) {
    check((await page.textContent("#summary")).includes(line), `${name}: the summary says "${line}"`);
  }
  check((await page.textContent("#replay-legend")).includes("goal region") === kind.commonroad,
        `${name}: goal regions in the legend only for a CommonRoad run`);
  check(errors.length === 0, `${name}: no console errors${errors.length ? ": " + errors.join(" | ") : ""}`);
  await page.close();
}

try {
  // --- a short drive, and a CommonRoad run on the same cycles ---
  await checkPage("run.html", {
    commonroad: false, incidents: "No incident", summary: [],
    plots: ["plot-speed", "plot-acc", "plot-jerk", "plot-lane", "plot-gap", "plot-headway", "plot-ms", "plot-cost"],
    noPlots: [], tiles: ["max speed", "max acc", "max jerk"], noTiles: [],
    ticks: { "plot-speed": "0 20 40 60", "plot-lane": "0 1 2" },
  });
  // The planner's speed cap, no simulator acceleration or jerk; the verdict's failure as its
  // incident; the road's lanes, goal regions and cars of their own sizes.
  await checkPage("commonroad.html", {
    commonroad: true, incidents: "collision at 20.0 s",
    summary: ["CommonRoad synthetic, planning problem 1", "NOT solved (stopped by collision)",
              "collision at step 200: with obstacle 3"],
    plots: ["plot-speed", "plot-lane", "plot-gap", "plot-headway", "plot-ms", "plot-cost"],
    noPlots: ["plot-acc", "plot-jerk"], tiles: ["max speed", "collision"], noTiles: ["max acc", "max jerk"],
    ticks: { "plot-speed": "0 20 40 60 80 100", "plot-lane": "0 1 2" },  // not 23.1 / 46.3...
  });
  // --- a drive with a collision ---
  {
    const { page, errors } = await open("incident.html");
    const incidentText = await page.textContent("#incidents");
    check(incidentText.includes("collision at 15.0 s"), `header lists the incident (${incidentText.trim()})`);
    const tiles = await page.$$eval(".tile.bad", (ts) => ts.map((t) => t.textContent));
    check(tiles.some((t) => t.startsWith("incidents1")) && tiles.some((t) => t.startsWith("collision1")),
          `header tiles flag it (${tiles.join(", ")})`);
    const allTiles = await page.$$eval(".tile", (ts) => ts.map((t) => t.textContent));
    check(allTiles.includes("plan p50 / p992.20 / 2.50 ms") && allTiles.some((t) => t.includes("0.39 mi")),
          "the simulator's footer shape is understood (plan_ms {p50, p99}, miles)");
    const marks = await incidentMarks(page);
    check(Object.values(marks).length >= 8 && Object.values(marks).every((v) => v > 0.5),
          `every plot marks the incident (${JSON.stringify(marks)})`);
    await page.click("#incidents button.incident");
    check((await page.textContent("#details")).includes("incident: collision"), "clicking it opens the cycle's details");
    check((await page.evaluate(() => window.freneticReport.state.k)) === 150, "and moves the replay to it");
    await page.screenshot({ path: path.join(args.out, "incident.png"), fullPage: true });
    check(errors.length === 0, `no console errors${errors.length ? ": " + errors.join(" | ") : ""}`);
    await page.close();
  }
  // The same marks must not appear without an incident (the check above can fail).
  {
    const { page } = await open("run.html");
    const marks = await incidentMarks(page);
    check(Object.values(marks).every((v) => v === 0), "a run without incident has no incident mark");
    await page.close();
  }
  if (args.large) {
    const { page, errors } = await open("large.html");
    await page.locator("#slider").fill(String(Math.floor(Number(args.large) / 3)));
    check(errors.length === 0, "large run: no console errors");
    await page.close();
  }
  check(outside.length === 0, `no request left the page${outside.length ? ": " + outside.join(", ") : ""}`);
} catch (e) {
  console.log(`FAIL ${e.stack || e}`);
  failures += 1;
} finally {
  await context.close();
  rmSync(userDataDir, { recursive: true, force: true });
}
console.log(failures ? `${failures} check(s) failed` : "all checks passed");
process.exit(failures ? 1 : 0);
