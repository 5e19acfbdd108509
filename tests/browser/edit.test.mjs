// End-to-end test of `dofplan edit` in headless Chromium (Debian's package,
// driven by playwright-core; no browser is downloaded).
//
//   DOFPLAN_BIN   the dofplan binary (default: target/release/dofplan)
//   CHROMIUM      the browser (default: /usr/bin/chromium)
//   DRAG_MOVES    drag moves per latency measurement (default: 240)
//   ONLY          run only the scenarios named, comma-separated (e.g. construct)
//   HIST          also print every painted drag latency (ms), to see their spread
//
// Screenshots go to target/browser-screenshots/. Exits non-zero on the
// first failed check, after printing what failed.

import { spawn, execFileSync } from "node:child_process";
import { existsSync, mkdirSync, mkdtempSync, readdirSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { createInterface } from "node:readline";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";

const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), "../..");
const BIN = resolve(ROOT, process.env.DOFPLAN_BIN ?? "target/release/dofplan");
const CHROMIUM = process.env.CHROMIUM ?? "/usr/bin/chromium";
const SHOTS = join(ROOT, "target/browser-screenshots");
const MOVES = Number(process.env.DRAG_MOVES ?? 240);
// A joint is closed when its two markers are this close, relative to the
// mechanism's size (the server refuses poses open by more than 1e-7).
const CLOSED = 1e-6;

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
  if (!ok) failures++;
}

function dofplan(...args) {
  return execFileSync(BIN, args, { cwd: ROOT, encoding: "utf8" });
}

/** Starts `dofplan edit FILE` in `cwd`; resolves with the URL it prints
 * first. */
function startEditor(file, cwd = ROOT) {
  const child = spawn(BIN, file ? ["edit", file] : ["edit"], { cwd, stdio: ["ignore", "pipe", "pipe"] });
  // Its standard error is shown only if it stops before printing its URL.
  let stderr = "";
  child.stderr.on("data", (d) => (stderr += d));
  return new Promise((ok, fail) => {
    const lines = createInterface({ input: child.stdout });
    lines.once("line", (url) => ok({ child, url }));
    child.once("exit", (code) =>
      fail(new Error(`dofplan edit ${file} exited (${code}) before printing its URL:\n${stderr}`)),
    );
  });
}

/** Every marker's world position from the DOM, by "body.marker". */
async function markers(page) {
  return page.$$eval("[data-marker]", (els) =>
    Object.fromEntries(els.map((e) => [e.dataset.marker, [Number(e.dataset.x), Number(e.dataset.y)]])),
  );
}

/** The largest gap between the two markers of a revolute joint, and the
 * mechanism's extent (to make it relative). */
async function worstJoint(page, joints) {
  const at = await markers(page);
  const xs = Object.values(at);
  const extent = Math.max(
    Math.max(...xs.map((p) => p[0])) - Math.min(...xs.map((p) => p[0])),
    Math.max(...xs.map((p) => p[1])) - Math.min(...xs.map((p) => p[1])),
  );
  let worst = 0;
  let name = "";
  for (const j of joints.filter((j) => j.kind === "revolute")) {
    const [a, b] = j.markers.map((k) => at[k]);
    if (!a || !b || !a.every(Number.isFinite) || !b.every(Number.isFinite)) return { gap: Infinity, name: j.name };
    const gap = Math.hypot(a[0] - b[0], a[1] - b[1]) / extent;
    if (gap > worst) [worst, name] = [gap, j.name];
  }
  return { gap: worst, name };
}

/** Waits until the page has no request in flight or queued. */
async function settled(page) {
  await page.waitForFunction(() => window.__dofplan.ready && !window.__dofplan.busy());
}

/** The document the page was sent (joints with their markers). */
async function documentOf(page) {
  return page.evaluate(() => window.__dofplan.doc());
}

const percentile = (xs, p) => {
  const s = xs.slice().sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.ceil((p / 100) * s.length) - 1)];
};

/** Drags from the centre of `selector` with real mouse events: `moves`
 * moves on a circle, each waited for until its pose is on screen. Returns
 * the round trips measured in the page. */
async function dragLatency(page, selector, moves, radius, eachFrame = null) {
  const box = await page.locator(selector).boundingBox();
  const [cx, cy] = [box.x + box.width / 2, box.y + box.height / 2];
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  const before = await page.evaluate(() => window.__dofplan.latencies.length);
  // Each wait below ends on one of the page's animation frames, so a move
  // sent at once would reach the page at the same point of every frame and
  // the figures would measure that phase, not the latency. A pause drawn
  // uniformly over one 60 Hz frame (seeded, so runs are comparable) spreads
  // the moves over the frame as a hand's are.
  let seed = 12345;
  const phase = () => {
    seed = (seed * 1103515245 + 12345) % 2147483648;
    return (seed / 2147483648) * (1000 / 60);
  };
  for (let i = 1; i <= moves; i++) {
    const t = (2 * Math.PI * i) / 60;
    await new Promise((r) => setTimeout(r, phase()));
    await page.mouse.move(cx + radius * Math.sin(t), cy - radius * (1 - Math.cos(t)));
    await page.waitForFunction((n) => window.__dofplan.latencies.length >= n, before + i);
    if (eachFrame) await eachFrame(i);
  }
  await page.mouse.up();
  await settled(page);
  const grabMs = await page.evaluate(() => window.__dofplan.grabMs);
  const all = await page.evaluate(() => ({
    rendered: window.__dofplan.latencies,
    dom: window.__dofplan.domLatencies,
    server: window.__dofplan.serverMs,
  }));
  return {
    rendered: all.rendered.slice(before),
    dom: all.dom.slice(before),
    server: all.server.slice(before),
    grabMs,
  };
}

function report(name, lat) {
  const f = (x) => x.toFixed(2);
  console.log(
    `     ${name}: ${lat.rendered.length} drag moves, pointer event → pose rendered (next animation frame): ` +
      `p50 ${f(percentile(lat.rendered, 50))} ms, p99 ${f(percentile(lat.rendered, 99))} ms; ` +
      `pointer event → DOM updated: p50 ${f(percentile(lat.dom, 50))} ms, p99 ${f(percentile(lat.dom, 99))} ms; ` +
      `of which solving on the server: p50 ${f(percentile(lat.server, 50))} ms, p99 ${f(percentile(lat.server, 99))} ms ` +
      `(the grab that set the drag up: ${f(lat.grabMs)} ms)`,
  );
  if (process.env.HIST) console.log(JSON.stringify(lat.rendered.map((x) => Math.round(x * 10) / 10)));
}

// Every editor page opened, with what it was opened on: none may log a
// failed request or an error in its console while its editor runs.
const PAGES = [];

async function openEditor(browser, file, cwd = ROOT, viewport = { width: 1400, height: 860 }) {
  const { child, url } = await startEditor(file, cwd);
  const page = await browser.newPage({ viewport });
  page.on("pageerror", (e) => check(false, `no script error on the page (${e.message})`));
  // What a person would see in the browser's console: failed requests (a
  // 404 for /favicon.ico, say) and errors.
  page.problems = [];
  PAGES.push([file ?? "a new document", page]);
  page.on("response", (r) => {
    if (r.status() >= 400) page.problems.push(`${r.status()} ${new URL(r.url()).pathname}`);
  });
  page.on("requestfailed", (r) => page.problems.push(`failed ${r.url()}`));
  page.on("console", (m) => {
    if (m.type() === "error") page.problems.push(`console: ${m.text()}`);
  });
  await page.goto(url);
  await settled(page);
  return { child, page, url };
}

/** Every `.toml` file under `dir` (relative, with "/"), not in target/ or
 * hidden folders: to compare the Open list with. */
function tomlFiles(dir, prefix = "") {
  const out = [];
  for (const e of readdirSync(join(dir, prefix), { withFileTypes: true })) {
    if (e.name.startsWith(".") || e.name === "target" || e.name === "node_modules") continue;
    const rel = prefix ? `${prefix}/${e.name}` : e.name;
    if (e.isDirectory()) out.push(...tomlFiles(dir, rel));
    else if (e.isFile() && e.name.endsWith(".toml")) out.push(rel);
  }
  return out;
}

/** The status box after the page's last request is answered. */
async function statusOf(page) {
  await settled(page);
  return page.$eval("#status", (e) => ({ kind: e.dataset.status, text: e.textContent }));
}

/** Whether an element's content fits its box sideways (wrapped, or
 * scrolled within itself), and its box is within the viewport. */
async function fits(page, selector) {
  return page.$eval(selector, (e) => {
    const r = e.getBoundingClientRect();
    return {
      wraps: e.scrollWidth <= e.clientWidth + 1,
      inside: r.right <= window.innerWidth + 0.5 && r.bottom <= window.innerHeight + 0.5 && r.top >= 0,
      scrolls: e.scrollHeight <= e.clientHeight + 1 || ["auto", "scroll"].includes(getComputedStyle(e).overflowY),
      mono: getComputedStyle(e).fontFamily.includes("mono"),
    };
  });
}

async function files(browser) {
  console.log("== the editor started at the repository's root: Open lists the mechanisms in its folders");
  const { child, page } = await openEditor(browser, null);
  try {
    const listed = await page.$$eval("#open-file option", (os) => os.map((o) => o.value));
    const mechanisms = tomlFiles(ROOT).filter((f) => f.startsWith("mechanisms/"));
    check(
      mechanisms.length > 10 && mechanisms.every((f) => listed.includes(f)),
      `every .toml of mechanisms/ and its folders is listed (${mechanisms.length}; missing: ${mechanisms.filter((f) => !listed.includes(f)).join(", ") || "none"})`,
    );
    check(listed.includes("mechanisms/spatial/rssr.toml"), "a file two folders down is listed (mechanisms/spatial/rssr.toml)");
    const others = listed.filter((f) => f.endsWith("Cargo.toml") || f === "rustfmt.toml" || f.startsWith("target/") || f.includes("/."));
    check(others.length === 0, `no Cargo.toml, rustfmt.toml, target/ or hidden file is listed (${others.join(", ") || "none"}; ${listed.length} listed)`);
    // A person picks one and presses Open.
    await page.selectOption("#open-file", "mechanisms/fourbar.toml");
    await page.click("#open");
    const s = await statusOf(page);
    const bodies = await page.$$eval("g[data-body]", (els) => els.map((e) => e.dataset.body));
    check(
      s.text === "opened mechanisms/fourbar.toml" && bodies.join() === "ground,crank,coupler,rocker",
      `Open reads a file of a folder (${s.text}; ${bodies})`,
    );
    const title = await page.title();
    check(title.startsWith("mechanisms/fourbar.toml"), `the page's title names the file (${title})`);
    check((await page.$eval('[data-panel="check"]', (e) => e.textContent)) === dofplan("check", "mechanisms/fourbar.toml"), "its Check panel is `dofplan check` run at the root");
    await page.screenshot({ path: join(SHOTS, "files-open-list.png") });
    check(page.problems.length === 0, `no failed request or console error, favicon included (${page.problems.join("; ") || "none"})`);
  } finally {
    child.kill();
  }
}

// fourbar with a typo in one joint's marker and a misspelt kind: two
// errors with places in the text.
const TYPO = readFileSync(join(ROOT, "mechanisms/fourbar.toml"), "utf8")
  .replace('markers = ["crank.B", "coupler.B"]', 'markers = ["crank.B", "coupler.Q"]')
  .replace('[joints.D]\nkind = "revolute"', '[joints.D]\nkind = "revolut"');

async function broken(browser) {
  console.log("== `dofplan edit typo.toml`: a file that does not load opens with its errors, and is fixed in the page");
  const dir = mkdtempSync(join(tmpdir(), "dofplan-edit-"));
  writeFileSync(join(dir, "typo.toml"), TYPO);
  const { child, page } = await openEditor(browser, "typo.toml", dir);
  try {
    const expected = (() => {
      try {
        execFileSync(BIN, ["check", "typo.toml"], { cwd: dir, encoding: "utf8", stdio: "pipe" });
        return "";
      } catch (e) {
        return e.stderr;
      }
    })();
    check(expected.includes("coupler.Q"), "`dofplan check typo.toml` refuses it (the test's premise)");
    const tab = await page.$eval("#tabs button.active", (b) => b.dataset.tab);
    const shown = await page.$eval("#file-errors", (e) => (e.hidden ? "" : e.textContent));
    const text = await page.$eval("#file-text", (e) => e.value);
    check(tab === "file" && text === TYPO, `the page opens on the File tab with the file's text (${tab})`);
    check(shown.includes("coupler.Q") && shown.includes("revolut"), "its errors are shown above the text");
    check((await page.$eval('[data-panel="check"]', (e) => e.textContent)).trim() === expected.trim(), "the Check panel is `dofplan check`'s report");
    const qLine = TYPO.split("\n").findIndex((l) => l.includes("coupler.Q")) + 1;
    const marked = await page.$$eval("#file-gutter .error-line", (els) => els.map((e) => Number(e.textContent)));
    check(marked.includes(qLine), `the gutter marks the error's line ${qLine} (${marked})`);
    const gotos = await page.$$eval("#file-errors .goto", (bs) => bs.map((b) => b.textContent));
    check(gotos.length >= 2, `a button per error's place (${gotos.join("; ")})`);
    const s0 = await statusOf(page);
    check(s0.kind === "error" && s0.text.includes("does not load"), `the status says it does not load (${s0.text})`);
    check((await page.locator("g[data-body]").count()) === 0, "nothing is drawn");
    let f = await fits(page, "#file-errors");
    check(f.wraps && f.inside && f.scrolls && f.mono, `the errors fit their panel: wrapped, in view, scrollable, monospace (${JSON.stringify(f)})`);
    f = await fits(page, "#tabs");
    check(f.inside, "the tabs stay on screen");
    await page.screenshot({ path: join(SHOTS, "broken-opened.png") });

    // The first error's button selects its place; typing the fix there.
    await page.click(`#file-errors .goto[data-line="${qLine}"]`);
    const selected = await page.$eval("#file-text", (e) => e.value.slice(e.selectionStart, e.selectionEnd));
    check(selected.includes("coupler.Q"), `the button selects the error's place in the text (${JSON.stringify(selected)})`);
    await page.keyboard.type('"coupler.B"');
    // Applied with one error left: the other's message, still not drawn.
    await page.click("#file-apply");
    let s = await statusOf(page);
    const left = await page.$eval("#file-errors", (e) => e.textContent);
    check(s.text.includes("still does not load (1 error)") && left.includes("revolut") && !left.includes("coupler.Q"), `Apply with one error left shows only that one (${s.text})`);
    // The second: select the misspelt kind and retype it, then Ctrl+Enter.
    const kLine = TYPO.split("\n").findIndex((l) => l.includes('"revolut"')) + 1;
    await page.click(`#file-errors .goto[data-line="${kLine}"]`);
    await page.keyboard.type('"revolute"');
    await page.keyboard.press("Control+Enter");
    s = await statusOf(page);
    const bodies = await page.$$eval("g[data-body]", (els) => els.map((e) => e.dataset.body));
    check(bodies.join() === "ground,crank,coupler,rocker" && s.text.includes("loads now"), `fixed: the four-bar is drawn and editable (${s.text})`);
    check((await page.$eval("#file-errors", (e) => e.hidden)) && (await page.$eval("#file", (e) => e.textContent)) === "typo.toml (unsaved)", "the errors are gone; the fix is not saved yet");
    check((await page.title()).startsWith("typo.toml (unsaved)"), `the title says so (${await page.title()})`);
    await page.screenshot({ path: join(SHOTS, "broken-fixed.png") });
    await page.keyboard.press("Escape");
    await page.locator("#canvas").click({ position: { x: 5, y: 300 } });
    await page.keyboard.press("Control+s");
    s = await statusOf(page);
    const fixed = TYPO.replace("coupler.Q", "coupler.B").replace('"revolut"', '"revolute"');
    check(readFileSync(join(dir, "typo.toml"), "utf8") === fixed, `Ctrl+S writes the fixed text (${s.text})`);
    const report = execFileSync(BIN, ["check", "typo.toml"], { cwd: dir, encoding: "utf8" });
    check(report.includes("= 1"), "`dofplan check typo.toml` accepts it now");

    // A text with many errors, applied to the valid document: refused,
    // and its long message fits the status box without pushing the tabs
    // off the screen.
    await page.click('#tabs button[data-tab="file"]');
    const many = fixed.replaceAll('kind = "revolute"', 'kind = "hinge-of-a-very-long-name-that-does-not-exist-anywhere-in-the-format"');
    await page.$eval("#file-text", (e, t) => {
      e.value = t;
      e.dispatchEvent(new Event("input", { bubbles: true }));
    }, many);
    await page.click("#file-apply");
    s = await statusOf(page);
    check(s.kind === "error" && (s.text.match(/error/g) || []).length >= 4, `a text with four errors is refused with check's message (${s.text.split("\n")[0]})`);
    f = await fits(page, "#status");
    check(f.wraps && f.inside && f.scrolls && f.mono, `the long message fits its box: wrapped, in view, scrollable, monospace (${JSON.stringify(f)})`);
    f = await fits(page, "#tabs");
    check(f.inside, "and the tabs stay on screen");
    check((await page.locator("g[data-body]").count()) === 4, "the drawing is as it was");
    await page.screenshot({ path: join(SHOTS, "broken-long-refusal.png") });
    check(page.problems.length === 0, `no failed request or console error (${page.problems.join("; ") || "none"})`);
  } finally {
    child.kill();
    rmSync(dir, { recursive: true, force: true });
  }
}

async function numericRefused(browser) {
  console.log("== mechanisms/slider_crank.toml: typed coordinates that would open a joint are refused with check's message");
  const { child, page } = await openEditor(browser, "mechanisms/slider_crank.toml");
  try {
    await page.keyboard.press("e");
    const s0 = (await markers(page))["slider.S"];
    const [x, y] = await page.evaluate((p) => window.__dofplan.toPage(p), s0);
    // Shift+click on the pin: the marker there (the slider's block, S).
    await page.keyboard.down("Shift");
    await page.mouse.click(x, y);
    await page.keyboard.up("Shift");
    const sel = await page.evaluate(() => window.__dofplan.selection());
    check(sel && sel.name === "slider.S", `Shift+click selects slider.S (${JSON.stringify(sel)})`);
    const before = await snapshot(page);
    await page.fill("#marker-y", "1");
    await page.press("#marker-y", "Enter");
    const s = await statusOf(page);
    check(
      s.kind === "error" && s.text.includes("mechanisms/slider_crank.toml:") && s.text.includes("`S`"),
      `slider.S typed off its slot's line is refused with check's message (${s.text.split("\n")[0]})`,
    );
    check(JSON.stringify(await snapshot(page)) === JSON.stringify(before), "and nothing changes");
    await page.screenshot({ path: join(SHOTS, "numeric-refused.png") });
  } finally {
    child.kill();
  }
}

async function newFile(browser) {
  console.log("== `dofplan edit new.toml` for a file that does not exist: a new document saved under that name");
  const dir = mkdtempSync(join(tmpdir(), "dofplan-edit-"));
  const { child, page } = await openEditor(browser, "new.toml", dir);
  try {
    const file = await page.$eval("#file", (e) => e.textContent);
    const name = await page.$eval("#name", (e) => e.textContent);
    check(file === "new.toml (unsaved)" && name === "new" && !existsSync(join(dir, "new.toml")), `a new document named after the file (${name}; ${file}); nothing written yet`);
    const pageOf = (p) => page.evaluate((q) => window.__dofplan.toPage(q), p);
    await page.keyboard.press("n");
    const [x, y] = await pageOf([2, 0]);
    await page.mouse.click(x, y);
    await statusOf(page);
    await page.keyboard.press("Control+s");
    let s = await statusOf(page);
    const written = existsSync(join(dir, "new.toml")) ? readFileSync(join(dir, "new.toml"), "utf8") : "";
    check(s.text === "saved new.toml" && written.startsWith('name = "new"'), `Ctrl+S writes new.toml, no name asked (${s.text})`);
    const report = execFileSync(BIN, ["check", "new.toml"], { cwd: dir, encoding: "utf8" });
    check(report.startsWith("new (new.toml)"), `\`dofplan check new.toml\` reads it (${report.split("\n")[0]})`);
    // Save as: the file, the mechanism's name and the title follow.
    await page.fill("#save-name", "pivots");
    await page.press("#save-name", "Enter");
    s = await statusOf(page);
    const shown = await page.evaluate(() => [document.querySelector("#name").textContent, document.querySelector("#file").textContent, document.title]);
    check(
      s.text === "saved pivots.toml (the mechanism is called pivots now)" && shown[0] === "pivots" && shown[1] === "pivots.toml" && shown[2].startsWith("pivots.toml"),
      `Save as: the page's name follows (${shown.join(" | ")}; ${s.text})`,
    );
    check(readFileSync(join(dir, "pivots.toml"), "utf8").startsWith('name = "pivots"'), "and the file's name = \"pivots\"");
    await page.screenshot({ path: join(SHOTS, "new-file-saved-as.png") });
  } finally {
    child.kill();
    rmSync(dir, { recursive: true, force: true });
  }
}

async function aids(browser) {
  console.log("== construction aids: grid and snapping, the pointer's coordinates, lengths, numeric entry, the sweep and traces");
  const dir = mkdtempSync(join(tmpdir(), "dofplan-edit-"));
  const { child, page } = await openEditor(browser, null, dir);
  try {
    const pageOf = (p) => page.evaluate((q) => window.__dofplan.toPage(q), p);
    const at = async (key) => (await markers(page))[key];
    const moveTo = async (p) => {
      const [x, y] = await pageOf(p);
      await page.mouse.move(x, y);
    };
    const click = async (p) => {
      const [x, y] = await pageOf(p);
      await page.mouse.click(x, y);
    };
    // G shows the grid; points placed by the pointer snap to it.
    await page.keyboard.press("g");
    const step = await page.evaluate(() => window.__dofplan.gridStep());
    const lines = await page.locator("#grid line").count();
    check(step > 0 && lines > 10 && (await page.getAttribute("#grid-toggle", "aria-pressed")) === "true", `G: a grid of step ${step} (${lines} lines)`);
    await page.keyboard.press("n");
    await click([2 + 0.3 * step, -0.3 * step]);
    let s = await statusOf(page);
    const a = await at("ground.A");
    check(a[0] === 2 && a[1] === 0, `a click 0.3 steps off (2, 0) puts ground.A exactly on it: (${a}) (${s.text})`);
    // The pointer's coordinates, on the grid.
    await moveTo([1 + 0.2 * step, 1 - 0.2 * step]);
    let readout = await page.$eval("#pointer", (e) => e.textContent);
    check(readout === "x 1  y 1", `the pointer's coordinates are shown, snapped (${JSON.stringify(readout)})`);
    await page.screenshot({ path: join(SHOTS, "aids-grid.png") });

    // Drawing a link: its length is shown while drawing.
    await page.keyboard.press("b");
    await click(await at("ground.O"));
    await moveTo([3 + 0.2 * step, 0.1 * step]);
    readout = await page.$eval("#pointer", (e) => e.textContent);
    let labels = await page.$$eval("#lengths text", (ts) => ts.map((t) => t.textContent));
    check(readout === "x 3  y 0  length 3" && labels.includes("3"), `while drawing, the segment's length: ${JSON.stringify(readout)}, labels ${labels}`);
    await page.screenshot({ path: join(SHOTS, "aids-drawing-length.png") });
    await click([3, 0]);
    await page.keyboard.press("Enter");
    s = await statusOf(page);
    check((await at("link1.B")).join() === "3,0", `link1 drawn from ground.O to (3, 0) (${s.text})`);

    // Edit mode: a click on the link selects it; its length is shown and
    // typed.
    await page.keyboard.press("e");
    await click([1.5, 0]);
    labels = await page.$$eval("#lengths text", (ts) => ts.map((t) => t.textContent));
    const box = await page.$eval("#length-box", (e) => !e.hidden);
    check(box && labels.includes("3") && (await page.inputValue("#length")) === "3", `a selected link shows its length (${labels}; field ${await page.inputValue("#length")})`);
    await page.fill("#length", "1.5");
    await page.press("#length", "Enter");
    s = await statusOf(page);
    let b = await at("link1.B");
    check(Math.abs(b[0] - 1.5) < 1e-12 && Math.abs(b[1]) < 1e-12, `typing 1.5 makes link1 1.5 long: link1.B at (${b}) (${s.text})`);
    // A marker dragged: its distance to the link's other marker is shown.
    const [bx, by] = await pageOf(b);
    const [tx, ty] = await pageOf([2, 2]);
    await page.mouse.move(bx, by);
    await page.mouse.down();
    for (let i = 1; i <= 8; i++) await page.mouse.move(bx + ((tx - bx) * i) / 8, by + ((ty - by) * i) / 8);
    labels = await page.$$eval("#lengths text", (ts) => ts.map((t) => t.textContent));
    check(labels.includes(String(Number(Math.hypot(2, 2).toFixed(4)))), `while dragging a marker, its distance to the link's other marker (${labels})`);
    await page.screenshot({ path: join(SHOTS, "aids-dragging-length.png") });
    await page.mouse.up();
    s = await statusOf(page);
    b = await at("link1.B");
    check(b[0] === 2 && b[1] === 2, `dropped on the grid point (2, 2): (${b}) (${s.text})`);
    // The marker selected: its coordinates typed.
    await click(b);
    const sel = await page.evaluate(() => window.__dofplan.selection());
    check(sel && sel.kind === "marker" && sel.name === "link1.B" && (await page.inputValue("#marker-x")) === "2", `a click on link1.B selects it; x and y fields show (${await page.inputValue("#marker-x")}, ${await page.inputValue("#marker-y")})`);
    await page.fill("#marker-x", "0.6");
    await page.fill("#marker-y", "-0.8");
    await page.press("#marker-y", "Enter");
    s = await statusOf(page);
    b = await at("link1.B");
    check(b[0] === 0.6 && b[1] === -0.8, `typed coordinates move link1.B to (0.6, -0.8): (${b}) (${s.text})`);

    // The pin made an input; a sweep set from the page (a wrong one
    // refused with check's message), a marker traced, the sweep played.
    await click([0, 0]);
    await page.keyboard.press("i");
    await statusOf(page);
    check((await page.locator('input[data-input="theta"]').count()) === 1, "the pin is the input theta");
    check(await page.$eval("#play", (e) => e.disabled), "no sweep yet: Play is disabled");
    await page.click("#sweep-summary");
    check(await page.$eval("#sweep-editor", (e) => e.open), "the Sweep box opens");
    await page.fill("#sweep-steps", "0");
    await page.click("#sweep-set");
    s = await statusOf(page);
    check(s.kind === "error" && s.text.includes("sweep.steps") && s.text.includes("untitled.toml:"), `0 steps is refused with check's message (${s.text.split("\n")[0]})`);
    await page.fill("#sweep-from", "0");
    await page.fill("#sweep-to", "360");
    await page.fill("#sweep-steps", "37");
    await page.press("#sweep-steps", "Enter");
    s = await statusOf(page);
    const summary = await page.$eval("#sweep-summary", (e) => e.textContent);
    check(summary === "Sweep: theta 0 → 360, 37 steps" && !(await page.$eval("#play", (e) => e.disabled)), `the sweep is set; Play is enabled (${summary}; ${s.text})`);
    await click(await at("link1.B"));
    await page.keyboard.press("t");
    s = await statusOf(page);
    const chips = await page.$$eval("#traced .chip", (cs) => cs.map((c) => c.dataset.traced));
    const trace = (await documentOf(page)).traces["link1.B"] || [];
    // Every point of the trace is 1 from the pin (|(0.6, -0.8)| = 1).
    const off = Math.max(...trace.map((p) => Math.abs(Math.hypot(p[0], p[1]) - 1)));
    check(chips.join() === "link1.B" && trace.length === 37 && off < 1e-9, `T traces link1.B: 37 points on the unit circle about the pin (largest error ${off.toExponential(2)}; ${s.text})`);
    check((await page.locator('path[data-trace="link1.B"]').getAttribute("d")).length > 100, "its trace is drawn");
    const frames = await page.evaluate(() => window.__dofplan.frames);
    await page.click("#play");
    await page.waitForFunction((n) => window.__dofplan.frames >= n + 20, frames);
    await page.click("#play");
    await settled(page);
    check(true, "the sweep built in the page plays");
    await page.screenshot({ path: join(SHOTS, "aids-sweep-traced.png") });
    await page.fill("#save-name", "crank");
    await page.click("#save-as");
    s = await statusOf(page);
    const sim = JSON.parse(execFileSync(BIN, ["simulate", "crank.toml", "--json"], { cwd: dir, encoding: "utf8" }));
    // The file is drawn at the pose on screen (wherever the playback
    // paused): frame 9 of 37 over 0–360° is frame 0 turned by 90°.
    const [p0, p9] = [sim.frames[0].markers["link1.B"], sim.frames[9].markers["link1.B"]];
    const turned = Math.hypot(p9[0] + p0[1], p9[1] - p0[0]);
    check(sim.frames.length === 37 && turned < 1e-9 && Math.abs(Math.hypot(...p0) - 1) < 1e-9, `saved: \`dofplan simulate crank.toml\` runs its 37 frames, frame 9 a quarter turn on (${turned.toExponential(2)}; ${s.text})`);
    // Untraced from its chip's ×.
    await page.click('#traced .chip[data-traced="link1.B"] button');
    s = await statusOf(page);
    check((await page.locator("#traced .chip").count()) === 0 && (await page.locator("path[data-trace]").count()) === 0, `the chip's × stops tracing (${s.text})`);
    // G again: no grid, no snapping.
    await page.keyboard.press("g");
    check((await page.locator("#grid line").count()) === 0, "G again hides the grid");
    check(page.problems.length === 0, `no failed request or console error (${page.problems.join("; ") || "none"})`);
  } finally {
    child.kill();
    rmSync(dir, { recursive: true, force: true });
  }
}

async function fourbar(browser) {
  console.log("== mechanisms/fourbar.toml");
  const { child, page, url } = await openEditor(browser, "mechanisms/fourbar.toml");
  try {
    // The token is needed: the same page without it is refused.
    const port = new URL(url).port;
    const bare = await fetch(`http://127.0.0.1:${port}/`);
    check(bare.status === 403, `a request without the token is refused (${bare.status})`);

    const bodies = await page.$$eval("g[data-body]", (els) => els.map((e) => e.dataset.body));
    check(
      JSON.stringify(bodies) === JSON.stringify(["ground", "crank", "coupler", "rocker"]),
      `a group per body (${bodies})`,
    );
    const drawn = await markers(page);
    check(Object.keys(drawn).length === 9, `a data-marker per marker (${Object.keys(drawn).length})`);
    check(drawn["coupler.P"][0] === 3 && drawn["coupler.P"][1] === 3.5, `coupler.P at its drawn (3, 3.5): ${drawn["coupler.P"]}`);
    const joints = await page.$$eval("[data-joint]", (els) => els.map((e) => e.dataset.joint));
    check(JSON.stringify(joints) === JSON.stringify(["A", "B", "C", "D"]), `a data-joint per joint (${joints})`);
    check((await page.locator('input[data-input="theta"]').count()) === 1, "a slider for input theta");
    check((await page.locator('path[data-trace="coupler.P"]').getAttribute("d"))?.length > 100, "the trace of coupler.P");
    const panel = async (name) => page.$eval(`[data-panel="${name}"]`, (e) => e.textContent);
    check((await panel("plan")) === dofplan("plan", "mechanisms/fourbar.toml"), "the Plan panel is `dofplan plan`");
    check((await panel("check")) === dofplan("check", "mechanisms/fourbar.toml"), "the Check panel is `dofplan check`");
    check((await panel("rust")) === dofplan("emit", "mechanisms/fourbar.toml"), "the Rust panel is `dofplan emit`");
    await page.screenshot({ path: join(SHOTS, "fourbar-drawn.png") });

    const doc = await documentOf(page);
    // The slider at 90°: every marker where `dofplan simulate` puts it.
    await page.$eval('input[data-input="theta"]', (s) => {
      s.value = "90";
      s.dispatchEvent(new Event("input", { bubbles: true }));
    });
    await settled(page);
    const at90 = await markers(page);
    const simulated = JSON.parse(
      dofplan("simulate", "mechanisms/fourbar.toml", "--from", "90", "--to", "90", "--steps", "1", "--json"),
    ).frames[0].markers;
    let off = 0;
    for (const [k, p] of Object.entries(simulated)) off = Math.max(off, Math.hypot(p[0] - at90[k][0], p[1] - at90[k][1]));
    check(off < 1e-9, `slider at 90°: markers as \`dofplan simulate\` at 90° (largest difference ${off.toExponential(2)})`);
    check(at90["crank.B"][0] !== drawn["crank.B"][0], `the slider moved crank.B (${drawn["crank.B"]} → ${at90["crank.B"]})`);
    let w = await worstJoint(page, doc.joints);
    check(w.gap < CLOSED, `every joint closed at 90° (worst ${w.name}: ${w.gap.toExponential(2)})`);
    await page.screenshot({ path: join(SHOTS, "fourbar-slider-90.png") });

    // Drag coupler.P along its coupler curve (the file's trace), 1.5 units
    // ahead: a one-DOF linkage can follow the pointer only along it.
    const startP = (await markers(page))["coupler.P"];
    const curve = doc.traces["coupler.P"];
    const near = (p) => Math.min(...curve.map((q) => Math.hypot(p[0] - q[0], p[1] - q[1])));
    const k = curve.reduce((best, q, i) => (Math.hypot(q[0] - startP[0], q[1] - startP[1]) < Math.hypot(curve[best][0] - startP[0], curve[best][1] - startP[1]) ? i : best), 0);
    const ahead = curve[(k + 12) % curve.length];
    const along = Math.hypot(ahead[0] - startP[0], ahead[1] - startP[1]);
    const target = [startP[0] + (1.5 * (ahead[0] - startP[0])) / along, startP[1] + (1.5 * (ahead[1] - startP[1])) / along];
    const [px, py] = await page.evaluate((p) => window.__dofplan.toPage(p), startP);
    const [tx, ty] = await page.evaluate((p) => window.__dofplan.toPage(p), target);
    await page.mouse.move(px, py);
    await page.mouse.down();
    for (let i = 1; i <= 30; i++) {
      await page.mouse.move(px + ((tx - px) * i) / 30, py + ((ty - py) * i) / 30);
      await page.waitForTimeout(5);
    }
    await settled(page);
    const endP = (await markers(page))["coupler.P"];
    const before = Math.hypot(startP[0] - target[0], startP[1] - target[1]);
    const after = Math.hypot(endP[0] - target[0], endP[1] - target[1]);
    check(after < 0.5 * before, `dragging coupler.P: it followed the pointer (distance ${before.toFixed(3)} → ${after.toFixed(3)})`);
    // The trace is a polyline of 1° steps: its chords stay within 0.01.
    check(near(endP) < 0.01, `coupler.P stayed on its coupler curve (${near(endP).toExponential(2)} off the trace)`);
    w = await worstJoint(page, doc.joints);
    check(w.gap < CLOSED, `every joint closed while dragging (worst ${w.name}: ${w.gap.toExponential(2)})`);
    await page.screenshot({ path: join(SHOTS, "fourbar-drag.png") });
    await page.mouse.up();
    await settled(page);
    const status = await page.$eval("#status", (e) => e.dataset.status);
    check(["solved", "stretched"].includes(status), `the drag's status is shown (${status})`);

    // After the drag the slider drives the mechanism from where it is.
    const dragged = await markers(page);
    await page.$eval('input[data-input="theta"]', (s) => {
      s.value = String(Number(s.value) + 20);
      s.dispatchEvent(new Event("input", { bubbles: true }));
    });
    await settled(page);
    const moved = await markers(page);
    check(moved["crank.B"][0] !== dragged["crank.B"][0], "after a drag, the slider still moves the mechanism");
    w = await worstJoint(page, doc.joints);
    check(w.gap < CLOSED, `every joint closed after the drag and slider (worst ${w.name}: ${w.gap.toExponential(2)})`);
    const errors = await page.evaluate(() => window.__dofplan.errors);
    check(errors.length === 0, `no error replies (${errors.join("; ")})`);

    // Malformed and hostile messages on a second connection: each gets an
    // error reply, and the server keeps serving.
    const replies = await page.evaluate(async () => {
      const ws = new WebSocket(`ws://${location.host}/ws${location.search}`);
      const got = [];
      ws.onmessage = (e) => got.push(JSON.parse(e.data));
      await new Promise((ok) => (ws.onopen = ok));
      for (const m of [
        "not json",
        JSON.stringify({ type: "inputs", id: 1, values: [1e400] }),
        '{"type":"inputs","id":2,"values":[NaN]}',
        JSON.stringify({ type: "inputs", id: 3, values: [1, 2, 3] }),
        JSON.stringify({ type: "grab", id: 4, body: "nobody", at: [0, 0] }),
        JSON.stringify({ type: "grab", id: 5, body: "ground", at: [0, 0] }),
        JSON.stringify({ type: "drag", id: 6, to: [1, 1] }),
        JSON.stringify({ type: "explode", id: 7 }),
        JSON.stringify({ type: "inputs", id: 8, values: [45] }),
      ]) {
        ws.send(m);
        await new Promise((r) => setTimeout(r, 20));
      }
      await new Promise((r) => setTimeout(r, 200));
      ws.close();
      return got.filter((m) => m.type !== "document").map((m) => [m.type, m.id, m.message ?? m.status]);
    });
    const errorsFor = replies.filter(([t]) => t === "error").length;
    check(errorsFor === 8, `8 bad messages, 8 error replies: ${JSON.stringify(replies.slice(1, 9))}`);
    const last = replies[replies.length - 1];
    check(last[0] === "frame" && last[1] === 8 && last[2] === "solved", `and the connection still solves (${last})`);

    // The assembly mode is the side of the line B→D that C is on: a smooth
    // drag never flips it.
    const side = (at) => {
      const [b, c, d] = [at["crank.B"], at["coupler.C"], at["ground.D"]];
      return Math.sign((d[0] - b[0]) * (c[1] - b[1]) - (d[1] - b[1]) * (c[0] - b[0]));
    };
    const mode = side(await markers(page));
    let flips = 0;
    const lat = await dragLatency(page, '[data-marker="coupler.P"]', MOVES, 40, async () => {
      if (side(await markers(page)) !== mode) flips++;
    });
    check(flips === 0, `no branch flip over ${MOVES} drag moves (${flips} frames on the other side of B→D)`);
    w = await worstJoint(page, doc.joints);
    check(w.gap < CLOSED, `every joint closed after ${MOVES} drag moves (worst ${w.name}: ${w.gap.toExponential(2)})`);
    report("fourbar", lat);
    await page.screenshot({ path: join(SHOTS, "fourbar-after-latency.png") });
    return lat;
  } finally {
    child.kill();
  }
}

async function stress(browser) {
  console.log("== mechanisms/stress_50.toml");
  const { child, page } = await openEditor(browser, "mechanisms/stress_50.toml");
  try {
    const doc = await documentOf(page);
    const n = await page.locator("[data-body]").count();
    check(n === doc.bodies.length && n === 50, `a group per body (${n})`);
    await page.screenshot({ path: join(SHOTS, "stress_50-drawn.png") });
    // The last coupler: the far end of the chain.
    const last = doc.bodies.filter((b) => b.name.startsWith("coupler")).pop();
    const marker = `${last.name}.${last.markers[last.markers.length - 1].name}`;
    const lat = await dragLatency(page, `[data-marker="${marker}"]`, MOVES, 25);
    const w = await worstJoint(page, doc.joints);
    check(w.gap < CLOSED, `every joint closed after dragging ${marker} (worst ${w.name}: ${w.gap.toExponential(2)})`);
    report(`stress_50 (dragging ${marker})`, lat);
    await page.screenshot({ path: join(SHOTS, "stress_50-dragged.png") });
    const errors = await page.evaluate(() => window.__dofplan.errors);
    check(errors.length === 0, `no error replies (${errors.join("; ")})`);
    return lat;
  } finally {
    child.kill();
  }
}

/** The floor of the painted figure: a page that does no work at all — it
 * moves a dot to the pointer synchronously in the same `pointerrawupdate`
 * handler and measures exactly as the editor does (event → DOM updated,
 * event → the next animation frame after it). Whatever a page does, its
 * pose cannot be painted before the browser's next frame; this says how
 * much of the editor's figure is that frame clock. */
async function baseline(browser) {
  console.log("== baseline: a page that answers the pointer with no work at all");
  const page = await browser.newPage({ viewport: { width: 1400, height: 860 } });
  try {
    // Served from a loopback address (answered by Playwright, nothing
    // listens there), so that it is a secure context like the editor's page:
    // Chromium gives `pointerrawupdate` only to those.
    const url = "http://127.0.0.1:9/baseline";
    await page.route(url, (route) => route.fulfill({ contentType: "text/html", body: BASELINE_PAGE }));
    await page.goto(url);
    check(
      await page.evaluate(() => window.isSecureContext && "onpointerrawupdate" in window),
      "the baseline page gets pointerrawupdate, as the editor does",
    );
    const lat = await dragLatency(page, "#dot", MOVES, 40);
    check(lat.rendered.length === MOVES, `the baseline page measured ${lat.rendered.length} moves`);
    report("baseline (no work, no server)", lat);
    return lat;
  } finally {
    await page.close();
  }
}

const BASELINE_PAGE = `<!doctype html><svg width="800" height="600" style="touch-action:none">
      <circle id="dot" cx="400" cy="300" r="6"/></svg>
      <script>
        window.__dofplan = { latencies: [], domLatencies: [], serverMs: [], grabMs: 0, ready: true, busy: () => false };
        const dot = document.getElementById("dot");
        let down = false;
        addEventListener("pointerdown", () => (down = true));
        addEventListener("pointerup", () => (down = false));
        addEventListener("pointerrawupdate", (e) => {
          if (!down) return;
          const t0 = Math.min(e.timeStamp, performance.now());
          dot.setAttribute("cx", e.clientX);
          dot.setAttribute("cy", e.clientY);
          const p = window.__dofplan;
          p.domLatencies.push(performance.now() - t0);
          p.serverMs.push(0);
          requestAnimationFrame(() => p.latencies.push(performance.now() - t0));
        });
      </script>`;

async function openChain(browser) {
  console.log("== mechanisms/drag/open_chain_15.toml (no inputs, 15 free DOF)");
  const { child, page } = await openEditor(browser, "mechanisms/drag/open_chain_15.toml");
  try {
    const doc = await documentOf(page);
    check((await page.locator("input[data-input]").count()) === 0, "no sliders: the file has no inputs");
    const panel = await page.$eval('[data-panel="plan"]', (e) => e.textContent);
    check(panel.startsWith("No plan: the mechanism has no inputs"), `the Plan panel says why there is no plan (${panel.split("\n")[0]})`);
    // Pull the free end 2 units up: an under-constrained chain reaches it.
    const start = (await markers(page))["link_15.E"];
    const target = [start[0] - 1, start[1] + 2];
    const [px, py] = await page.evaluate((p) => window.__dofplan.toPage(p), start);
    const [tx, ty] = await page.evaluate((p) => window.__dofplan.toPage(p), target);
    await page.mouse.move(px, py);
    await page.mouse.down();
    for (let i = 1; i <= 25; i++) {
      await page.mouse.move(px + ((tx - px) * i) / 25, py + ((ty - py) * i) / 25);
      await page.waitForTimeout(5);
    }
    await settled(page);
    await page.screenshot({ path: join(SHOTS, "open_chain_15-drag.png") });
    await page.mouse.up();
    await settled(page);
    const end = (await markers(page))["link_15.E"];
    const left = Math.hypot(end[0] - target[0], end[1] - target[1]);
    // The pointer is at a pixel: the target is known to a pixel's width.
    const pixel = await page.evaluate(() => 1 / window.__dofplan.scale());
    check(left < 2 * pixel, `the chain's free end reached the pointer (${left.toExponential(2)} away)`);
    const w = await worstJoint(page, doc.joints);
    check(w.gap < CLOSED, `every joint closed (worst ${w.name}: ${w.gap.toExponential(2)})`);
  } finally {
    child.kill();
  }
}

async function pendulum(browser) {
  console.log("== tests/browser/fixtures/pendulum.toml (a link hanging on one pin)");
  const { child, page } = await openEditor(browser, "tests/browser/fixtures/pendulum.toml");
  try {
    const doc = await documentOf(page);
    // Grab the link halfway down and pull to the right, beyond its reach:
    // it turns about the pin to point at the pointer.
    const [px, py] = await page.evaluate((p) => window.__dofplan.toPage(p), [0, -1]);
    const [tx, ty] = await page.evaluate((p) => window.__dofplan.toPage(p), [3, -1]);
    await page.mouse.move(px, py);
    await page.mouse.down();
    for (let i = 1; i <= 25; i++) {
      await page.mouse.move(px + ((tx - px) * i) / 25, py + ((ty - py) * i) / 25);
      await page.waitForTimeout(5);
    }
    await settled(page);
    await page.screenshot({ path: join(SHOTS, "pendulum-drag.png") });
    await page.mouse.up();
    await settled(page);
    const at = await markers(page);
    const [ex, ey] = at["link.E"];
    // The link from the pin through the pointer (3, -1), at its length 2.
    const want = [(2 * 3) / Math.hypot(3, 1), (2 * -1) / Math.hypot(3, 1)];
    const off = Math.hypot(ex - want[0], ey - want[1]);
    const pixel = await page.evaluate(() => 1 / window.__dofplan.scale());
    check(off < 2 * pixel, `the link turned about its pin toward the pointer (link.E ${off.toExponential(2)} from the line to it)`);
    const w = await worstJoint(page, doc.joints);
    check(w.gap < CLOSED, `its pin stayed closed (${w.gap.toExponential(2)})`);
  } finally {
    child.kill();
  }
}

async function forces(browser) {
  console.log("== mechanisms/loads/fourbar_weights.toml (the forces that hold the pose, as arrows)");
  const { child, page } = await openEditor(browser, "mechanisms/loads/fourbar_weights.toml");
  try {
    const doc = await documentOf(page);
    check(!(await page.locator("#forces-toggle").isHidden()), "a file with loads offers the Forces button");
    check((await page.locator("#forces [data-force]").count()) === 0, "no arrows until asked");
    await page.click("#forces-toggle");
    await settled(page);
    // At each slider value: the input torque the page shows (from the
    // bodies' equilibrium) against `dofplan analyze --forces` at that
    // angle (virtual work with the plan's rates, another path), and each
    // joint's arrow along the CLI's reaction.
    for (const theta of [0, 75, 210]) {
      await page.$eval('input[data-input="theta"]', (e, v) => {
        e.value = String(v);
        e.dispatchEvent(new Event("input", { bubbles: true }));
      }, theta);
      await settled(page);
      const cli = JSON.parse(dofplan("analyze", "mechanisms/loads/fourbar_weights.toml", "--forces", "--json", "--from", String(theta), "--to", String(theta), "--steps", "1"));
      const want = cli.frames[0].input_force.theta;
      const shown = Number(await page.$eval('[data-input-force="theta"]', (e) => e.dataset.value));
      check(Math.abs(shown - want) < 1e-9 * Math.max(1, Math.abs(want)), `theta = ${theta}: the input torque shown is the CLI's (${shown.toFixed(6)} against ${want.toFixed(6)})`);
      for (const j of doc.joints) {
        const [fx, fy] = cli.frames[0].reactions[j.name];
        const arrow = page.locator(`#forces [data-force="${j.name}"]`);
        const got = JSON.parse(await arrow.getAttribute("data-vector"));
        const off = Math.hypot(got[0] - fx, got[1] - fy);
        check(off < 1e-9 * Math.max(1, Math.hypot(fx, fy)), `theta = ${theta}: joint ${j.name}'s arrow is its reaction (${got.map((v) => v.toFixed(3))})`);
        // Drawn from the joint's pin, pointing along the force (screen y
        // is down).
        const line = arrow.locator("line");
        if ((await line.count()) === 1) {
          const [x1, y1, x2, y2] = await Promise.all(["x1", "y1", "x2", "y2"].map(async (k) => Number(await line.getAttribute(k))));
          const cos = ((x2 - x1) * fx - (y2 - y1) * fy) / (Math.hypot(x2 - x1, y2 - y1) * Math.hypot(fx, fy));
          check(cos > 0.9999, `theta = ${theta}: joint ${j.name}'s arrow points along it (cos ${cos.toFixed(6)})`);
        }
      }
      if (theta === 75) await page.screenshot({ path: join(SHOTS, "fourbar_weights-forces.png") });
    }
    await page.click("#forces-toggle");
    await settled(page);
    check((await page.locator("#forces [data-force]").count()) === 0, "the button hides them again");
  } finally {
    child.kill();
  }
  // A file without loads has no such button.
  const plain = await openEditor(browser, "mechanisms/fourbar.toml");
  try {
    check(await plain.page.locator("#forces-toggle").isHidden(), "a file without loads has no Forces button");
  } finally {
    plain.child.kill();
  }
  // In space: the Cardan drive against 10 N m, its arrows projected.
  const cardan = await openEditor(browser, "mechanisms/loads/cardan_torque.toml");
  try {
    const { page } = cardan;
    const doc = await documentOf(page);
    await page.click("#forces-toggle");
    await settled(page);
    for (const theta of [30, 100]) {
      await page.$eval('input[data-input="theta"]', (e, v) => {
        e.value = String(v);
        e.dispatchEvent(new Event("input", { bubbles: true }));
      }, theta);
      await settled(page);
      const cli = JSON.parse(dofplan("analyze", "mechanisms/loads/cardan_torque.toml", "--forces", "--json", "--from", String(theta), "--to", String(theta), "--steps", "1"));
      const want = cli.frames[0].input_force.theta;
      const shown = Number(await page.$eval('[data-input-force="theta"]', (e) => e.dataset.value));
      check(Math.abs(shown - want) < 1e-9 * Math.max(1, Math.abs(want)), `cardan at ${theta}: the input torque shown is the CLI's (${shown.toFixed(6)} against ${want.toFixed(6)})`);
      for (const j of doc.joints) {
        const f = cli.frames[0].reactions[j.name];
        const got = JSON.parse(await page.locator(`#forces [data-force="${j.name}"]`).getAttribute("data-vector"));
        const off = Math.hypot(...got.map((v, i) => v - f[i]));
        check(got.length === 3 && off < 1e-9 * Math.max(1, Math.hypot(...f)), `cardan at ${theta}: joint ${j.name}'s arrow is its reaction (${got.map((v) => v.toFixed(3))})`);
      }
      const note = await page.$eval("#forces .not-held", (e) => e.textContent).catch(() => "");
      check(note.includes("not unique") && ["A", "B", "U"].every((j) => note.includes(j)), `cardan at ${theta}: its redundant joints are named (${note})`);
      if (theta === 100) await page.screenshot({ path: join(SHOTS, "cardan_torque-forces.png") });
    }
  } finally {
    cardan.child.kill();
  }
}

async function limits(browser) {
  console.log("== mechanisms/rocker_rocker.toml (breaks past its limits)");
  const { child, page } = await openEditor(browser, "mechanisms/rocker_rocker.toml");
  try {
    const doc = await documentOf(page);
    const held = await markers(page);
    await page.$eval('input[data-input="theta"]', (s) => {
      s.value = "90";
      s.dispatchEvent(new Event("input", { bubbles: true }));
    });
    await settled(page);
    const status = await page.$eval("#status", (e) => ({ kind: e.dataset.status, text: e.textContent }));
    check(status.kind === "limited", `theta = 90° is past the limit: status ${status.kind}`);
    // The breaking step's explanation, as `dofplan plan` writes step 2.
    const step2 = dofplan("plan", "mechanisms/rocker_rocker.toml")
      .split("\n")[3]
      .trim()
      .replace(/^2\s+/, "")
      .replace(/\s+\[[^\]]*\]$/, "");
    check(status.text.includes("step 2 broke") && status.text.includes(step2), `the status names the breaking step: ${JSON.stringify(status.text)}`);
    const w = await worstJoint(page, doc.joints);
    check(w.gap < CLOSED, `the pose held at the limit has every joint closed (worst ${w.name}: ${w.gap.toExponential(2)})`);
    const now = await markers(page);
    check(now["coupler.C"][0] === held["coupler.C"][0], "limit: the mechanism stays at the last pose that closed");
    await page.screenshot({ path: join(SHOTS, "rocker_rocker-limited.png") });
    // Search goes to the break point instead.
    await page.selectOption("#policy", "search");
    await settled(page);
    const searched = await page.$eval("#status", (e) => e.dataset.status);
    check(searched === "searched", `search: status ${searched}`);
    const atBreak = await markers(page);
    check(atBreak["coupler.C"][0] !== held["coupler.C"][0], "search: the mechanism moved to the break point");
    const w2 = await worstJoint(page, doc.joints);
    check(w2.gap < CLOSED, `the pose at the break point has every joint closed (worst ${w2.name}: ${w2.gap.toExponential(2)})`);
    await page.screenshot({ path: join(SHOTS, "rocker_rocker-searched.png") });
  } finally {
    child.kill();
  }
}

async function sliderCrank(browser) {
  console.log("== mechanisms/slider_crank.toml (a prismatic joint; the sweep played)");
  const { child, page } = await openEditor(browser, "mechanisms/slider_crank.toml");
  try {
    const doc = await documentOf(page);
    const prismatic = doc.joints.filter((j) => j.kind === "prismatic").map((j) => j.name);
    check(prismatic.length > 0, `the file has a prismatic joint (${prismatic})`);
    for (const name of prismatic) {
      check((await page.locator(`[data-joint="${name}"].prismatic rect`).count()) === 1, `joint ${name} drawn as a slider block`);
    }
    const before = await page.evaluate(() => window.__dofplan.frames);
    await page.click("#play");
    await page.waitForFunction((n) => window.__dofplan.frames >= n + 30, before);
    await page.screenshot({ path: join(SHOTS, "slider_crank-playing.png") });
    await page.click("#play");
    await settled(page);
    const after = await page.evaluate(() => window.__dofplan.frames);
    check(after >= before + 30, `playing the sweep streams frames (${after - before})`);
    const playing = await page.$eval("#play", (b) => b.dataset.playing);
    check(playing === "false", "pause stops it");
    await page.waitForTimeout(200);
    check((await page.evaluate(() => window.__dofplan.frames)) === after, "no frame after pausing");
    const w = await worstJoint(page, doc.joints);
    check(w.gap < CLOSED, `every revolute joint closed (worst ${w.name}: ${w.gap.toExponential(2)})`);
  } finally {
    child.kill();
  }
}

async function empty(browser) {
  console.log("== a new document (no file)");
  const { child, page } = await openEditor(browser, null);
  try {
    const bodies = await page.$$eval("g[data-body]", (els) => els.map((e) => e.dataset.body));
    check(JSON.stringify(bodies) === '["ground"]', `the ground alone (${bodies})`);
    check((await page.locator('[data-marker="ground.O"]').count()) === 1, "its marker ground.O");
    const check_ = await page.$eval('[data-panel="check"]', (e) => e.textContent);
    check(check_.startsWith("untitled (untitled.toml)"), `the Check panel reports the new document (${check_.split("\n")[0]})`);
    await page.screenshot({ path: join(SHOTS, "empty.png") });
  } finally {
    child.kill();
  }
}

/** A snapshot of what the page draws: markers with their positions, joints
 * with their kinds, sliders, and the panels. */
async function snapshot(page) {
  return page.evaluate(() => ({
    markers: Array.from(document.querySelectorAll("[data-marker]")).map((e) => [e.dataset.marker, e.dataset.x, e.dataset.y]),
    joints: Array.from(document.querySelectorAll("[data-joint]")).map((e) => [e.dataset.joint, e.getAttribute("class")]),
    inputs: Array.from(document.querySelectorAll("input[data-input]")).map((e) => e.dataset.input),
    plan: document.querySelector('[data-panel="plan"]').textContent,
    check: document.querySelector('[data-panel="check"]').textContent,
    rust: document.querySelector('[data-panel="rust"]').textContent,
  }));
}

async function construct(browser) {
  console.log("== a four-bar built by mouse and keyboard from a new document, saved in a temporary directory");
  const dir = mkdtempSync(join(tmpdir(), "dofplan-edit-"));
  const { child, page } = await openEditor(browser, null, dir);
  try {
    const pageOf = (p) => page.evaluate((q) => window.__dofplan.toPage(q), p);
    const at = async (key) => (await markers(page))[key];
    const click = async (p) => {
      const [x, y] = await pageOf(p);
      await page.mouse.click(x, y);
    };
    /** Waits for the reply to the last request; the status it left. */
    const status = async () => {
      await settled(page);
      return page.$eval("#status", (e) => ({ kind: e.dataset.status, text: e.textContent }));
    };
    const jointsOf = async () => (await documentOf(page)).joints;

    // A second ground pivot, four units to the right of O.
    await page.keyboard.press("n");
    await click([4, 0]);
    let s = await status();
    const pivot = await at("ground.A");
    check(Boolean(pivot) && Math.hypot(pivot[0] - 4, pivot[1]) < 0.05, `Marker mode: a click adds ground.A at (4, 0): ${pivot} (${s.text})`);

    // The crank: from O (snapped) to (1, 1), finished with Enter.
    await page.keyboard.press("b");
    await click(await at("ground.O"));
    await click([1, 1]);
    await page.screenshot({ path: join(SHOTS, "construct-drawing-crank.png") });
    await page.keyboard.press("Enter");
    s = await status();
    let joints = await jointsOf();
    check(
      (await page.locator('[data-body="link1"]').count()) === 1 && joints.length === 1 && joints[0].markers.join() === "ground.O,link1.A",
      `Body mode: link1 drawn from ground.O, joined there (${JSON.stringify(joints)}; ${s.text})`,
    );
    // The coupler, from the crank's end to (3.5, 2.5).
    await click(await at("link1.B"));
    await click([3.5, 2.5]);
    await page.keyboard.press("Enter");
    await status();
    // The rocker, from the coupler's end to near the pivot (not on it),
    // finished with a double-click.
    await click(await at("link2.B"));
    const [rx, ry] = await pageOf([4.4, 0.5]);
    await page.mouse.dblclick(rx, ry);
    s = await status();
    joints = await jointsOf();
    check(joints.length === 3, `three links, three pins (${joints.map((j) => j.markers.join("–")).join(", ")}; ${s.text})`);
    // Edit mode: drop the rocker's end onto the pivot — it snaps and joins.
    await page.keyboard.press("e");
    const [fx, fy] = await pageOf(await at("link3.B"));
    const [gx, gy] = await pageOf(pivot);
    await page.mouse.move(fx, fy);
    await page.mouse.down();
    for (let i = 1; i <= 10; i++) await page.mouse.move(fx + ((gx + 3 - fx) * i) / 10, fy + ((gy - 2 - fy) * i) / 10);
    await page.screenshot({ path: join(SHOTS, "construct-snapping.png") });
    await page.mouse.up();
    s = await status();
    joints = await jointsOf();
    const last = joints[joints.length - 1];
    check(joints.length === 4 && last.markers.join() === "ground.A,link3.B", `dropped within a few pixels, link3.B snapped onto ground.A and joined (${last.markers}; ${s.text})`);
    let w = await worstJoint(page, joints);
    check(w.gap < CLOSED, `every joint of the built four-bar closed (worst ${w.name}: ${w.gap.toExponential(2)})`);
    // Dragging the pivot 0.2 to the left moves the ground's marker (the
    // plan is rebuilt); the rocker's end, pinned to it, goes with it.
    const [hx, hy] = await pageOf(pivot);
    const [kx, ky] = await pageOf([pivot[0] - 0.2, pivot[1]]);
    await page.mouse.move(hx, hy);
    await page.mouse.down();
    for (let i = 1; i <= 8; i++) await page.mouse.move(hx + ((kx - hx) * i) / 8, hy + ((ky - hy) * i) / 8);
    await page.mouse.up();
    s = await status();
    const pivot2 = await at("ground.A");
    check(Math.abs(pivot2[0] - (pivot[0] - 0.2)) < 0.02 && Math.abs(pivot2[1] - pivot[1]) < 0.02, `a dragged pivot moves (${pivot} → ${pivot2}; ${s.text})`);
    w = await worstJoint(page, joints);
    check(w.gap < CLOSED && (await jointsOf()).length === 4, `its pin moved with it and stays closed (worst ${w.name}: ${w.gap.toExponential(2)})`);
    let text = await page.$eval('[data-panel="check"]', (e) => e.textContent);
    check(text.includes("= 1") && text.includes("mobility"), `the Check panel has mobility 1 (${text.split("\n")[2]})`);

    // A click on the crank's pin selects the joint; I makes it the input.
    await click(await at("ground.O"));
    const selected = await page.evaluate(() => window.__dofplan.selection());
    check(selected && selected.kind === "joint" && selected.name === "J1", `a click on a pin selects its joint (${JSON.stringify(selected)})`);
    await page.keyboard.press("i");
    s = await status();
    check((await page.locator('input[data-input="theta"]').count()) === 1, `I: joint J1 is an input, with a slider (${s.text})`);
    text = await page.$eval('[data-panel="plan"]', (e) => e.textContent);
    check(!text.startsWith("No plan"), `the Plan panel has a plan (${text.split("\n")[0]})`);
    await page.screenshot({ path: join(SHOTS, "construct-fourbar-built.png") });

    // A refused edit: a second input on the same joint. check's message,
    // and nothing changes.
    const before = await snapshot(page);
    await page.keyboard.press("i");
    s = await status();
    const message = "error: input `theta2` drives joint `J1`, already driven by input `theta`";
    check(s.kind === "error" && s.text.includes(message) && s.text.includes("untitled.toml:"), `a refused edit shows check's message: ${JSON.stringify(s.text.split("\n").slice(0, 2))}`);
    check(JSON.stringify(await snapshot(page)) === JSON.stringify(before), "and changes nothing on the page");
    await page.screenshot({ path: join(SHOTS, "construct-refused.png") });

    // The slider turns the crank; every pin stays closed.
    const crankB = await at("link1.B");
    await page.$eval('input[data-input="theta"]', (e) => {
      e.value = "40";
      e.dispatchEvent(new Event("input", { bubbles: true }));
    });
    s = await status();
    const turned = await at("link1.B");
    check(Math.hypot(turned[0] - crankB[0], turned[1] - crankB[1]) > 0.5, `the slider turned the crank (${s.kind}: link1.B ${crankB} → ${turned})`);
    w = await worstJoint(page, joints);
    check(w.gap < CLOSED, `every revolute joint closed at theta = 40° (worst ${w.name}: ${w.gap.toExponential(2)})`);

    // P and R toggle the coupler–rocker pin; the pose on screen (the
    // slider's) becomes the drawing first.
    const moved = await markers(page);
    await click(await at("link2.B"));
    await page.keyboard.press("p");
    s = await status();
    const drawn = await markers(page);
    let off = 0;
    for (const [k, p] of Object.entries(moved)) off = Math.max(off, Math.hypot(p[0] - drawn[k][0], p[1] - drawn[k][1]));
    check(off < 1e-9, `an edit after a slider move is made at the pose on screen (markers moved ${off.toExponential(2)})`);
    check((await page.locator('[data-joint="J3"].prismatic').count()) === 1, `P: J3 is prismatic (${s.text})`);
    // Its line, editable: 30° from the x axis.
    await page.fill("#direction", "30");
    await page.press("#direction", "Tab");
    s = await status();
    const line = (await documentOf(page)).bodies.find((b) => b.name === "link2").markers.find((m) => m.name === "B").dir;
    check(
      Math.abs(line[0] - Math.cos(Math.PI / 6)) < 1e-9 && Math.abs(line[1] - 0.5) < 1e-9,
      `the prismatic joint's line set to 30° (${line}; ${s.text})`,
    );
    await page.screenshot({ path: join(SHOTS, "construct-prismatic.png") });
    const prismatic = await snapshot(page);
    await page.keyboard.press("r");
    s = await status();
    check((await page.locator('[data-joint="J3"].revolute').count()) === 1, `R: J3 is revolute again (${s.text})`);
    const revolute = await snapshot(page);

    // Undo and redo restore the page.
    await page.keyboard.press("Control+z");
    await status();
    check(JSON.stringify(await snapshot(page)) === JSON.stringify(prismatic), "Ctrl+Z: the page is as it was before R");
    await page.keyboard.press("Control+Shift+z");
    await status();
    check(JSON.stringify(await snapshot(page)) === JSON.stringify(revolute), "Ctrl+Shift+Z: and as it was after R");
    await page.click("#undo");
    await status();
    await page.click("#redo");
    await status();
    check(JSON.stringify(await snapshot(page)) === JSON.stringify(revolute), "the Undo and Redo buttons too");

    // Save: a name out of the directory is refused; a plain one is written.
    await page.$eval('input[data-input="theta"]', (e) => {
      e.value = "-30";
      e.dispatchEvent(new Event("input", { bubbles: true }));
    });
    await status();
    const onScreen = await markers(page);
    // Ctrl+S on a new document asks for a name first.
    await page.keyboard.press("Control+s");
    s = await status();
    const focused = await page.evaluate(() => document.activeElement.id);
    check(s.kind === "error" && s.text.includes("no file yet") && focused === "save-name", `Ctrl+S on a new document asks for a name (${s.text}; focus on #${focused})`);
    await page.fill("#save-name", "../x");
    await page.click("#save-as");
    s = await status();
    check(s.kind === "error" && s.text.includes("not a file name inside") && !existsSync(join(dir, "../x.toml")), `"../x" is refused (${s.text})`);
    await page.fill("#save-name", "built");
    await page.click("#save-as");
    s = await status();
    const saved = join(dir, "built.toml");
    check(existsSync(saved) && s.text === "saved built.toml (the mechanism is called built now)", `saved as built.toml in the editor's directory (${s.text})`);
    const run = (...args) => execFileSync(BIN, args, { cwd: dir, encoding: "utf8" });
    const report = run("check", "built.toml");
    const valid = report.includes("= 1") && report.includes("closed form");
    check(valid, `\`dofplan check built.toml\`: valid, mobility 1, closed form${valid ? "" : `\n${report}`}`);
    check((await page.$eval('[data-panel="plan"]', (e) => e.textContent)) === run("plan", "built.toml"), "its `dofplan plan` is the plan shown");
    check((await page.$eval('[data-panel="check"]', (e) => e.textContent)) === report, "its `dofplan check` is the Check panel");
    const fileMarkers = JSON.parse(run("simulate", "built.toml", "--from", "0", "--to", "0", "--steps", "1", "--json")).frames[0].markers;
    off = 0;
    for (const [k, p] of Object.entries(onScreen)) off = Math.max(off, Math.hypot(p[0] - fileMarkers[k][0], p[1] - fileMarkers[k][1]));
    check(
      Object.keys(fileMarkers).length === Object.keys(onScreen).length && off < 1e-9,
      `the saved file's drawing is the pose that was on screen (largest difference ${off.toExponential(2)})`,
    );
    const file = await page.$eval("#file", (e) => e.textContent);
    check(file === "built.toml", `the page names the file (${file})`);
    // A change, then Save (no name needed now) writes it back.
    await page.keyboard.press("n");
    await click([2, -1]);
    await status();
    await page.click("#save");
    s = await status();
    check(readFileSync(saved, "utf8").includes("B = [2"), `Save writes the change back to built.toml (${s.text})`);
    await page.screenshot({ path: join(SHOTS, "construct-saved.png") });

    // Deleting the coupler (selected by a click on it) takes its pins.
    await page.keyboard.press("e");
    const [c0, c1] = [await at("link2.A"), await at("link2.B")];
    await click([(c0[0] + c1[0]) / 2, (c0[1] + c1[1]) / 2]);
    await page.keyboard.press("Delete");
    s = await status();
    check((await page.locator('[data-body="link2"]').count()) === 0 && (await jointsOf()).length === 2, `Delete: the coupler and its two pins are gone (${s.text})`);
    // Open the saved file again, dropping the deletion.
    await page.selectOption("#open-file", "built.toml");
    await page.click("#open");
    s = await status();
    check(s.kind === "error" && s.text.includes("unsaved changes"), `Open asks before dropping unsaved changes (${s.text})`);
    await page.click("#open");
    s = await status();
    check((await page.locator('[data-body="link2"]').count()) === 1, `the second Open reads built.toml again (${s.text})`);
    // The wheel zooms about the pointer; a middle-button drag pans. The
    // world positions stay; their place on the page moves.
    const pin = await at("ground.O");
    const [ox, oy] = await pageOf(pin);
    const scale = await page.evaluate(() => window.__dofplan.scale());
    await page.mouse.move(ox, oy);
    await page.mouse.wheel(0, -300);
    await page.waitForFunction((s0) => window.__dofplan.scale() > s0, scale);
    const zoomed = await page.evaluate(() => window.__dofplan.scale());
    const [zx, zy] = await pageOf(pin);
    check(zoomed > 1.3 * scale && Math.hypot(zx - ox, zy - oy) < 1, `the wheel zooms about the pointer (scale ×${(zoomed / scale).toFixed(2)}, ground.O stays under it)`);
    await page.mouse.down({ button: "middle" });
    await page.mouse.move(ox + 60, oy + 40, { steps: 5 });
    await page.mouse.up({ button: "middle" });
    const [qx, qy] = await pageOf(pin);
    check(Math.hypot(qx - ox - 60, qy - oy - 40) < 1 && (await at("ground.O"))[0] === pin[0], `a middle-button drag pans (ground.O moved ${(qx - ox).toFixed(1)}, ${(qy - oy).toFixed(1)} px on the page)`);
    await page.screenshot({ path: join(SHOTS, "construct-zoomed.png") });
    const errors = await page.evaluate(() => window.__dofplan.errors);
    check(errors.length === 3, `three refusals in all, each shown (${errors.length})`);
  } finally {
    child.kill();
    rmSync(dir, { recursive: true, force: true });
  }
}

async function spatial(browser) {
  console.log("== mechanisms/spatial/rssr.toml (a spatial file: shown in 3D, not edited)");
  const file = "mechanisms/spatial/rssr.toml";
  const { child, page } = await openEditor(browser, file);
  try {
    const doc = await documentOf(page);
    check(doc.dimension === 3 && (await page.locator("[data-body]").count()) === doc.bodies.length, `a group per body of the 3D file (${doc.bodies.length})`);
    const zs = await page.$$eval("[data-marker]", (els) => els.map((e) => e.dataset.z));
    check(zs.length > 0 && zs.every((z) => z !== undefined && Number.isFinite(Number(z))), `every marker carries data-z (${zs.length})`);
    const panel = async (name) => page.$eval(`[data-panel="${name}"]`, (e) => e.textContent);
    check((await panel("plan")) === dofplan("plan", file), "the Plan panel is `dofplan plan`");
    check((await panel("check")) === dofplan("check", file), "the Check panel is `dofplan check`");
    check((await panel("rust")) === dofplan("emit", file), "the Rust panel is `dofplan emit`");
    check((await page.locator('path[data-trace]').count()) > 0, "the sweep's traces are drawn");
    await page.screenshot({ path: join(SHOTS, "rssr-3d.png") });

    // The slider at 40°: every marker where `dofplan simulate` puts it.
    await page.$eval('input[data-input="theta"]', (e) => {
      e.value = "40";
      e.dispatchEvent(new Event("input", { bubbles: true }));
    });
    await settled(page);
    const at = await page.$$eval("[data-marker]", (els) =>
      Object.fromEntries(els.map((e) => [e.dataset.marker, [Number(e.dataset.x), Number(e.dataset.y), Number(e.dataset.z)]])),
    );
    const simulated = JSON.parse(dofplan("simulate", file, "--from", "40", "--to", "40", "--steps", "1", "--json")).frames[0].markers;
    let off = 0;
    for (const [k, p] of Object.entries(simulated)) off = Math.max(off, Math.hypot(...p.map((v, c) => v - at[k][c])));
    check(off < 1e-9, `slider at 40°: markers as \`dofplan simulate\` at 40° (largest difference ${off.toExponential(2)})`);

    // As the CLI's views: a ground mark under each ground marker, each
    // revolute joint's axis (none for a ball joint), a floor grid.
    const marks = await page.$$eval(".ground-mark", (gs) => gs.map((g) => g.dataset.ground));
    check(marks.join() === "ground.A,ground.D", `a ground mark under each ground marker (${marks})`);
    const axes = await page.$$eval("[data-joint]", (gs) =>
      gs.map((g) => {
        const l = g.querySelector("line.joint-axis");
        return [g.dataset.joint, l.getAttribute("visibility"), ...["x1", "y1", "x2", "y2"].map((a) => Number(l.getAttribute(a)))];
      }),
    );
    const shownAxes = axes.filter((a) => a[1] === "visible").map((a) => a[0]);
    check(shownAxes.join() === "A,D", `the revolute joints' axes are drawn, not the ball joints' (${shownAxes})`);
    // Joint D's axis is the ground's: (1, 0, 1) from ground.D, whatever the
    // slider; on the page, along the projection of that line.
    const d = simulated["ground.D"];
    const [p0, p1] = await page.evaluate(([q, r]) => [window.__dofplan.project(q), window.__dofplan.project(r)], [d, [d[0] + 1, d[1], d[2] + 1]]);
    const [, , ax1, ay1, ax2, ay2] = axes.find((a) => a[0] === "D");
    const cross = ((ax2 - ax1) * (p1[1] - p0[1]) - (ay2 - ay1) * (p1[0] - p0[0])) / (Math.hypot(ax2 - ax1, ay2 - ay1) * Math.hypot(p1[0] - p0[0], p1[1] - p0[1]));
    const mid = Math.hypot((ax1 + ax2) / 2 - p0[0], (ay1 + ay2) / 2 - p0[1]);
    check(Math.abs(cross) < 1e-3 && mid < 0.05, `joint D's axis is drawn through ground.D along (1, 0, 1) (sine ${cross.toExponential(2)}, centre ${mid.toFixed(3)} px off)`);
    const floor = await page.$eval("#floor", (g) => ({ lines: g.querySelectorAll("line").length, z: Number(g.dataset.z) }));
    const lowest = Math.min(...doc.traces ? Object.values(doc.traces).flat().map((p) => p[2]) : [], ...Object.values(simulated).map((p) => p[2]), 0);
    check(floor.lines > 4 && floor.z <= lowest + 1e-12, `a floor grid under the lowest point (${floor.lines} lines at z = ${floor.z})`);

    // Dragging the view orbits it: the world positions stay, the drawing turns.
    const before = await page.evaluate(() => window.__dofplan.camera());
    const [px, py] = await page.evaluate((p) => window.__dofplan.toPage(p), simulated["coupler.C"]);
    const box = await page.locator("#canvas").boundingBox();
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width / 2 + 80, box.y + box.height / 2 + 20, { steps: 8 });
    await page.mouse.up();
    await settled(page);
    const after = await page.evaluate(() => window.__dofplan.camera());
    const [qx, qy] = await page.evaluate((p) => window.__dofplan.toPage(p), simulated["coupler.C"]);
    const still = await page.$eval('[data-marker="coupler.C"]', (e) => [Number(e.dataset.x), Number(e.dataset.y), Number(e.dataset.z)]);
    check(
      Math.abs(after.yaw - before.yaw - 0.8) < 1e-9 && Math.hypot(qx - px, qy - py) > 5 && Math.hypot(...still.map((v, c) => v - at["coupler.C"][c])) === 0,
      `a drag orbits the view (yaw +${(after.yaw - before.yaw).toFixed(2)} rad; coupler.C moved ${Math.hypot(qx - px, qy - py).toFixed(1)} px on the page, not in the world)`,
    );
    const shown = await page.$eval('[data-marker="coupler.C"]', (e) => [Number(e.getAttribute("cx")), Number(e.getAttribute("cy"))]);
    check(Math.hypot(box.x + shown[0] - qx, box.y + shown[1] - qy) < 0.5, "and the marker is drawn where the view projects it");
    await page.screenshot({ path: join(SHOTS, "rssr-3d-orbited.png") });

    // The sweep plays.
    const frames = await page.evaluate(() => window.__dofplan.frames);
    await page.click("#play");
    await page.waitForFunction((n) => window.__dofplan.frames >= n + 30, frames);
    await page.click("#play");
    await settled(page);
    check(true, "playing the 3D sweep streams frames");
    // Nothing edits it: the edit modes are off, and the server refuses.
    const disabled = await page.$$eval('[data-mode="body"], [data-mode="edit"], #save, #save-as, #open', (bs) => bs.map((b) => b.disabled));
    check(disabled.every(Boolean), `the edit modes, Save and Open are disabled (${disabled})`);
    const refused = await page.evaluate(async () => {
      const ws = new WebSocket(`ws://${location.host}/ws${location.search}`);
      const got = [];
      ws.onmessage = (e) => got.push(JSON.parse(e.data));
      await new Promise((ok) => (ws.onopen = ok));
      ws.send(JSON.stringify({ type: "edit", id: 7, edits: [{ op: "delete_body", body: "coupler" }] }));
      ws.send(JSON.stringify({ type: "grab", id: 8, body: "coupler", at: [0, 0] }));
      await new Promise((r) => setTimeout(r, 300));
      ws.close();
      return got.filter((m) => m.type === "error").map((m) => m.id);
    });
    check(JSON.stringify(refused) === "[7,8]", `an edit and a drag of a spatial file are refused (${refused})`);
    await page.screenshot({ path: join(SHOTS, "rssr-3d-played.png") });
  } finally {
    child.kill();
  }
}

/** Moves the slider of input `name` to `value`, as a person would. */
async function setInput(page, name, value) {
  await page.$eval(`input[data-input="${name}"]`, (e, v) => {
    e.value = String(v);
    e.dispatchEvent(new Event("input", { bubbles: true }));
  }, value);
  await settled(page);
}

/** A gear pair's drawing: per circle its body, centre and radius on screen
 * (canvas pixels) and in the world (data-x, data-y, data-r), and its tick
 * (from, to, in pixels); a rack's pitch line's ends. */
async function gearOf(page, name) {
  return page.$eval(`#gears [data-gear="${name}"]`, (g) => {
    const n = (e, k) => Number(e.getAttribute(k));
    const ticks = Array.from(g.querySelectorAll("line.gear-tick"));
    const circles = Array.from(g.querySelectorAll("circle.pitch")).map((c, k) => ({
      body: c.dataset.gearBody,
      ring: c.classList.contains("ring"),
      stroke: c.getAttribute("stroke"),
      px: [n(c, "cx"), n(c, "cy")],
      pr: n(c, "r"),
      at: [Number(c.dataset.x), Number(c.dataset.y)],
      r: Number(c.dataset.r),
      tick: [[n(ticks[k], "x1"), n(ticks[k], "y1")], [n(ticks[k], "x2"), n(ticks[k], "y2")]],
    }));
    const l = g.querySelector("line.rack-pitch");
    const rack = l && {
      body: l.dataset.gearBody,
      px: [[n(l, "x1"), n(l, "y1")], [n(l, "x2"), n(l, "y2")]],
      from: JSON.parse(l.dataset.from),
      to: JSON.parse(l.dataset.to),
      ticks: (g.querySelector("path.rack-ticks").getAttribute("d").match(/M/g) || []).length,
    };
    return { circles, rack };
  });
}

// Angles on screen (y down) in degrees, counter-clockwise as in the world.
const screenAngle = (from, to) => (Math.atan2(-(to[1] - from[1]), to[0] - from[0]) * 180) / Math.PI;
// The smaller angle between two directions, degrees.
const between = (a, b) => Math.abs((((a - b) % 360) + 540) % 360 - 180);

async function gears(browser) {
  console.log("== mechanisms/gears/: pitch circles that mesh on screen (epicyclic), a rack's pitch line, a geared drag refused");
  const dir = mkdtempSync(join(tmpdir(), "dofplan-edit-"));
  for (const f of ["epicyclic.toml", "rack_pinion.toml", "geared_fivebar.toml"]) writeFileSync(join(dir, f), readFileSync(join(ROOT, "mechanisms/gears", f), "utf8"));
  // The rack and pinion without its input (nor the sweep of it): nothing
  // plans its motion, and the drag does not model gears.
  const rackText = readFileSync(join(ROOT, "mechanisms/gears/rack_pinion.toml"), "utf8");
  writeFileSync(join(dir, "still.toml"), rackText.slice(0, rackText.indexOf("[inputs.theta]")).replace('name = "rack_pinion"', 'name = "still"'));
  const { child, page } = await openEditor(browser, "epicyclic.toml", dir);
  try {
    const doc = await documentOf(page);
    const colourOf = (body) => ["#2563eb", "#dc2626", "#059669", "#d97706", "#7c3aed", "#0891b2", "#db2777", "#65a30d"][doc.bodies.findIndex((b) => b.name === body) % 8];
    const names = await page.$$eval("#gears [data-gear]", (els) => els.map((e) => e.dataset.gear));
    check(names.join() === "sp,pr", `a data-gear per gear pair (${names})`);
    check(
      JSON.stringify(doc.gears.map((g) => [g.name, g.kind, g.bodies, g.radii, g.internal, g.carrier])) ===
        JSON.stringify([["sp", "gear", ["sun", "planet"], [2, 1], false, "arm"], ["pr", "gear", ["planet", "ring"], [1, 4], true, "arm"]]),
      "the document names each pair's bodies, radii, mesh and carrier",
    );
    const scale = await page.evaluate(() => window.__dofplan.scale());
    const project = (p) => page.evaluate((q) => window.__dofplan.project(q), p);
    // The drawing: each circle about its body's pivot as drawn, its radius
    // at the view's scale, in its body's colour.
    const expected = { sun: [[0, 0], 2], planet: [[3, 0], 1], ring: [[0, 0], 4] };
    let sp = await gearOf(page, "sp");
    let pr = await gearOf(page, "pr");
    for (const c of [...sp.circles, ...pr.circles]) {
      const [centre, r] = expected[c.body];
      const want = await project(centre);
      const off = Math.hypot(c.px[0] - want[0], c.px[1] - want[1]);
      check(off < 0.01 && Math.abs(c.pr - r * scale) < 0.01, `${c.body}'s circle about its pivot ${JSON.stringify(centre)}, radius ${r} (${off.toFixed(3)} px off, ${c.pr} px against ${(r * scale).toFixed(2)})`);
      check(c.stroke === colourOf(c.body), `${c.body}'s circle in its body's colour (${c.stroke})`);
    }
    const [sun, planet] = sp.circles;
    const ring = pr.circles[1];
    check(ring.ring && !sun.ring && !planet.ring && !pr.circles[0].ring, "the ring's circle is drawn as a ring, the others not");
    check(Math.abs(sun.pr / planet.pr - 2) < 1e-3 && Math.abs(ring.pr / planet.pr - 4) < 1e-3, `radii on screen 2 : 1 : 4 (${sun.pr} : ${planet.pr} : ${ring.pr} px)`);
    const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);
    // Tangent: externally (centres r1 + r2 apart), internally (r2 − r1).
    const tangent = (sp, pr) => [dist(sp.circles[0].px, sp.circles[1].px) - sp.circles[0].pr - sp.circles[1].pr, dist(pr.circles[0].px, pr.circles[1].px) - (pr.circles[1].pr - pr.circles[0].pr)];
    let [ext, int] = tangent(sp, pr);
    check(Math.abs(ext) < 0.03 && Math.abs(int) < 0.03, `the circles touch on screen: sun and planet (${ext.toFixed(3)} px), planet inside the ring (${int.toFixed(3)} px)`);
    // As drawn, each pair's ticks meet where the circles touch.
    const pitchSp = await project([2, 0]);
    const pitchPr = await project([4, 0]);
    check(dist(sun.tick[1], pitchSp) < 0.01 && dist(planet.tick[1], pitchSp) < 0.01, "the sun's and the planet's ticks meet at their pitch point (2, 0)");
    check(dist(pr.circles[0].tick[1], pitchPr) < 0.01 && dist(ring.tick[0], pitchPr) < 0.01, "the planet's and the ring's ticks meet at their pitch point (4, 0)");
    await page.screenshot({ path: join(SHOTS, "gears-epicyclic-drawn.png") });

    // The arm turned 60° with the sun held still (sun_rel = −carrier): the
    // planet rolls 60° round the sun, turning c(1 + rS/rP) = 180°, and the
    // ring c(1 + rS/rR) = 90°.
    await setInput(page, "carrier", 60);
    await setInput(page, "sun_rel", -60);
    const s1 = await statusOf(page);
    check(s1.kind === "solved", `carrier 60°, sun_rel −60°: solved (${s1.text})`);
    sp = await gearOf(page, "sp");
    pr = await gearOf(page, "pr");
    const [sun1, planet1] = sp.circles;
    const ring1 = pr.circles[1];
    const orbit = screenAngle(sun1.px, planet1.px);
    check(Math.abs(orbit - 60) < 0.05 && Math.abs(dist(sun1.px, planet1.px) - 3 * scale) < 0.02, `the planet's circle went 60° round the sun's (${orbit.toFixed(3)}°, ${(dist(sun1.px, planet1.px) / scale).toFixed(4)} from it)`);
    const wantAt = [3 * Math.cos(Math.PI / 3), 3 * Math.sin(Math.PI / 3)];
    check(dist(planet1.at, wantAt) < 1e-9 && dist(sun1.at, [0, 0]) < 1e-9, `its centre at (3 cos 60°, 3 sin 60°) in the world (${planet1.at.map((v) => v.toFixed(6))})`);
    check(dist(pr.circles[0].px, planet1.px) < 0.01 && dist(ring1.px, sun1.px) < 0.01, "the planet's two circles move together; the ring stays about O");
    [ext, int] = tangent(sp, pr);
    check(Math.abs(ext) < 0.03 && Math.abs(int) < 0.03, `still touching: sun and planet (${ext.toFixed(3)} px), planet and ring (${int.toFixed(3)} px)`);
    // Each tick turned with its body: the sun's not at all, the planet's
    // 180°, the ring's 90°.
    const tickAngle = (c) => screenAngle(c.tick[0], c.tick[1]);
    check(between(tickAngle(sun1), 0) < 0.1, `the sun's tick still points along +x (${tickAngle(sun1).toFixed(2)}°)`);
    check(between(tickAngle(planet1), 0) < 0.1, `the planet's tick (drawn toward the sun, along −x) turned 180° (${tickAngle(planet1).toFixed(2)}°)`);
    check(between(tickAngle(ring1), 90) < 0.1, `the ring's tick turned 90° (${tickAngle(ring1).toFixed(2)}°)`);
    // Rolling without slip: from where the circles touch now, the ticks
    // are equal arcs away on each (r·angle, in world units).
    const arcs = (a, b) => [a, b].map((c, k) => (c.r * Math.PI * between(tickAngle(c), screenAngle(c.px, [a, b][1 - k].px))) / 180);
    const [aSun, aPlanet] = arcs(sun1, planet1);
    check(Math.abs(aSun - aPlanet) < 1e-3 && aSun > 1, `sun and planet rolled equal arcs from their pitch point (${aSun.toFixed(4)}, ${aPlanet.toFixed(4)})`);
    // Inside the ring the pitch point is beyond the planet, away from O.
    const away = screenAngle(ring1.px, pr.circles[0].px);
    const aRing = (ring1.r * Math.PI * between(tickAngle(ring1), away)) / 180;
    const aPlanet2 = (pr.circles[0].r * Math.PI * between(tickAngle(pr.circles[0]), away)) / 180;
    check(Math.abs(aRing - aPlanet2) < 1e-3 && aRing > 1, `planet and ring rolled equal arcs from theirs (${aPlanet2.toFixed(4)}, ${aRing.toFixed(4)})`);
    await page.screenshot({ path: join(SHOTS, "gears-epicyclic-turned.png") });

    // A geared mechanism with inputs is dragged through its plan: the
    // planet's circle pulled, the arm follows.
    const errorsBefore = await page.evaluate(() => window.__dofplan.errors.length);
    const [gx, gy] = await page.evaluate((p) => window.__dofplan.toPage(p), wantAt);
    const target = [3 * Math.cos((100 * Math.PI) / 180), 3 * Math.sin((100 * Math.PI) / 180)];
    const [hx, hy] = await page.evaluate((p) => window.__dofplan.toPage(p), target);
    await page.mouse.move(gx, gy);
    await page.mouse.down();
    for (let i = 1; i <= 20; i++) {
      await page.mouse.move(gx + ((hx - gx) * i) / 20, gy + ((hy - gy) * i) / 20);
      await page.waitForTimeout(5);
    }
    await settled(page);
    await page.mouse.up();
    await settled(page);
    sp = await gearOf(page, "sp");
    const pulled = screenAngle(sp.circles[0].px, sp.circles[1].px);
    const errorsAfter = await page.evaluate((n) => window.__dofplan.errors.slice(n), errorsBefore);
    check(Math.abs(pulled - 100) < 0.5 && errorsAfter.length === 0, `dragging the planet took it round the sun to the pointer, at 100° (${pulled.toFixed(2)}°; errors: ${errorsAfter.join("; ") || "none"})`);
    [ext, int] = tangent(sp, await gearOf(page, "pr"));
    check(Math.abs(ext) < 0.03 && Math.abs(int) < 0.03, `after the drag the circles still touch (${ext.toFixed(3)}, ${int.toFixed(3)} px)`);

    // The rack and pinion: its pitch line tangent to the pinion's circle,
    // sliding r·θ when the pinion turns θ.
    await page.selectOption("#open-file", "rack_pinion.toml");
    await page.click("#open");
    await statusOf(page);
    const scaleR = await page.evaluate(() => window.__dofplan.scale());
    let rp = await gearOf(page, "R");
    check(rp.circles.length === 1 && rp.circles[0].body === "pinion" && rp.rack && rp.rack.body === "rack", "rack_pinion.toml: the pinion's circle and the rack's pitch line");
    const lineGap = (g) => {
      const [[x1, y1], [x2, y2]] = g.rack.px;
      const [cx, cy] = g.circles[0].px;
      return Math.abs((x2 - x1) * (y1 - cy) - (x1 - cx) * (y2 - y1)) / Math.hypot(x2 - x1, y2 - y1) - g.circles[0].pr;
    };
    check(Math.abs(lineGap(rp)) < 0.02 && Math.abs(rp.circles[0].pr - scaleR) < 0.01, `the pitch line touches the pinion's circle (${lineGap(rp).toFixed(3)} px)`);
    const line = (await documentOf(page)).gears[0].line;
    const marks = Math.floor(line.to / line.step) - Math.ceil(line.from / line.step) + 1;
    check(rp.rack.ticks === marks && marks >= 5, `its tick marks, a twelfth of the pinion's turn apart (${rp.rack.ticks} of ${marks})`);
    const from0 = rp.rack.from;
    await setInput(page, "theta", 45);
    rp = await gearOf(page, "R");
    const slid = rp.rack.from[0] - from0[0];
    check(Math.abs(slid - Math.PI / 4) < 1e-9 && Math.abs(rp.rack.from[1] - from0[1]) < 1e-12, `theta 45°: the pitch line slid r·π/4 along x (${slid.toFixed(6)})`);
    check(Math.abs(lineGap(rp)) < 0.02, `and still touches the circle (${lineGap(rp).toFixed(3)} px)`);
    const pinionTick = screenAngle(rp.circles[0].tick[0], rp.circles[0].tick[1]);
    check(between(pinionTick, -90 + 45) < 0.1, `the pinion's tick turned 45° from straight down (${pinionTick.toFixed(2)}°)`);
    await page.screenshot({ path: join(SHOTS, "gears-rack-pinion.png") });
    await setInput(page, "theta", -60);
    rp = await gearOf(page, "R");
    check(Math.abs(rp.rack.from[0] - from0[0] + Math.PI / 3) < 1e-9, `theta −60°: slid back r·π/3 (${(rp.rack.from[0] - from0[0]).toFixed(6)})`);

    // The geared five-bar: its cranks' circles (r 1 and 2) touch, turning
    // opposite ways at half the speed.
    await page.selectOption("#open-file", "geared_fivebar.toml");
    await page.click("#open");
    await statusOf(page);
    await setInput(page, "theta", 120);
    const g5 = await gearOf(page, "g");
    const gap5 = dist(g5.circles[0].px, g5.circles[1].px) - g5.circles[0].pr - g5.circles[1].pr;
    const [t1, t2] = g5.circles.map((c) => screenAngle(c.tick[0], c.tick[1]));
    check(Math.abs(gap5) < 0.03 && between(t1, 120) < 0.1 && between(t2, 180 - 60) < 0.1, `geared_fivebar at 120°: the cranks' circles touch (${gap5.toFixed(3)} px), crank1's tick turned 120°, crank2's −60° (${t1.toFixed(2)}°, ${t2.toFixed(2)}°)`);
    await page.screenshot({ path: join(SHOTS, "gears-geared-fivebar.png") });

    // Without an input nothing moves it: a drag is refused, and says so
    // where errors are shown, the message not replaced by the drag's
    // later moves or its release.
    await page.selectOption("#open-file", "still.toml");
    await page.click("#open");
    await statusOf(page);
    const stillDoc = await documentOf(page);
    check(stillDoc.gears.length === 1 && stillDoc.inputs.length === 0, "still.toml: the rack and pinion without its input");
    const planPanel = await page.$eval('[data-panel="plan"]', (e) => e.textContent);
    check(planPanel.includes("no inputs") && planPanel.includes("gear pair R"), `its Plan panel says it has no plan, and that a geared mechanism is dragged only through one (${planPanel})`);
    const still = await markers(page);
    const errors0 = await page.evaluate(() => window.__dofplan.errors.length);
    const [rx, ry] = await page.evaluate((p) => window.__dofplan.toPage(p), [1, -1]);
    await page.mouse.move(rx, ry);
    await page.mouse.down();
    for (let i = 1; i <= 10; i++) {
      await page.mouse.move(rx + 6 * i, ry);
      await page.waitForTimeout(5);
    }
    await settled(page);
    let s = await statusOf(page);
    await page.screenshot({ path: join(SHOTS, "gears-drag-refused.png") });
    check(s.kind === "error" && s.text.includes("geared") && s.text.includes("gear pair R") && s.text.includes("no inputs"), `dragging the rack is refused, said in the status (${s.text.replace(/\n/g, " | ")})`);
    await page.mouse.up();
    s = await statusOf(page);
    const errors = await page.evaluate((n) => window.__dofplan.errors.slice(n), errors0);
    check(s.kind === "error" && s.text.includes("geared") && errors.length === 1, `the refusal stays shown after the release, the only error (${errors.length}: ${errors.map((e) => e.split("\n")[0]).join("; ")})`);
    check(JSON.stringify(await markers(page)) === JSON.stringify(still), "and nothing moved");
    const grabbedClass = await page.$$eval("g.body.grabbed", (els) => els.length);
    const dot = await page.$eval("#grab-point", (e) => e.getAttribute("visibility"));
    check(grabbedClass === 0 && dot === "hidden", "the body is let go");
    check(page.problems.length === 0, `no failed request or console error (${page.problems.join("; ") || "none"})`);
  } finally {
    child.kill();
    rmSync(dir, { recursive: true, force: true });
  }
}

/** A slot's drawing: its ends on screen (canvas pixels, from its lines)
 * and in the world (data-from, data-to), its outline's colour, and its
 * pin's centre on screen. */
async function slotOf(page, name) {
  return page.$eval(`#slots [data-slot="${name}"]`, (g) => {
    const n = (e, k) => Number(e.getAttribute(k));
    const edge = g.querySelector("line.slot-edge");
    const lines = Array.from(g.querySelectorAll("line")).map((l) => [n(l, "x1"), n(l, "y1"), n(l, "x2"), n(l, "y2")]);
    const pin = g.querySelector("circle.slot-pin");
    return {
      body: g.dataset.slotBody,
      px: [[n(edge, "x1"), n(edge, "y1")], [n(edge, "x2"), n(edge, "y2")]],
      together: lines.every((l) => JSON.stringify(l) === JSON.stringify(lines[0])),
      width: n(edge, "stroke-width"),
      stroke: edge.getAttribute("stroke"),
      from: JSON.parse(g.dataset.from),
      to: JSON.parse(g.dataset.to),
      pin: [n(pin, "cx"), n(pin, "cy")],
      pinRadius: n(pin, "r"),
    };
  });
}

/** Marker `key`'s centre on screen (canvas pixels). */
async function markerPx(page, key) {
  return page.$eval(`[data-marker="${key}"]`, (c) => [Number(c.getAttribute("cx")), Number(c.getAttribute("cy"))]);
}

/** Where `p` is along the segment from `a` to `b` (0 at a, 1 at b), and
 * how far off its line (pixels). */
function alongSegment(p, [a, b]) {
  const d = [b[0] - a[0], b[1] - a[1]];
  const len = Math.hypot(d[0], d[1]);
  const v = [p[0] - a[0], p[1] - a[1]];
  return { t: (v[0] * d[0] + v[1] * d[1]) / (len * len), off: Math.abs(v[0] * d[1] - v[1] * d[0]) / len, len };
}

async function slots(browser) {
  console.log("== mechanisms/slots/: a slot drawn along the rocker and turning with it (quick_return), a pin held at its slot's end (scotch_yoke, short slot)");
  const dir = mkdtempSync(join(tmpdir(), "dofplan-edit-"));
  writeFileSync(join(dir, "quick_return.toml"), readFileSync(join(ROOT, "mechanisms/slots/quick_return.toml"), "utf8"));
  // The scotch yoke with its slot cut short: the pin, sin(30° + θ) up it,
  // reaches the end 0.8 at θ = asin(0.8) − 30° ≈ 23.13°.
  const yoke = readFileSync(join(ROOT, "mechanisms/slots/scotch_yoke.toml"), "utf8");
  check(yoke.includes("ends = [-1.25, 1.25]"), "scotch_yoke.toml's slot ends are ±1.25, to cut short");
  writeFileSync(join(dir, "short_yoke.toml"), yoke.replace("ends = [-1.25, 1.25]", "ends = [-0.8, 0.8]").replace('name = "scotch_yoke"', 'name = "short_yoke"'));
  const { child, page } = await openEditor(browser, "quick_return.toml", dir);
  try {
    const doc = await documentOf(page);
    const colourOf = (body) => ["#2563eb", "#dc2626", "#059669", "#d97706", "#7c3aed", "#0891b2", "#db2777", "#65a30d"][doc.bodies.findIndex((b) => b.name === body) % 8];
    const names = await page.$$eval("[data-slot]", (els) => els.map((e) => e.dataset.slot));
    check(names.join() === "S", `one data-slot, S (${names})`);
    const d = doc.slots[0];
    check(
      JSON.stringify([d.name, d.body, d.marker, d.pin, d.ends]) === JSON.stringify(["S", "rocker", "rocker.S", "crank.A", [0.9, 3.1]]),
      `the document names the slot's body, marker, pin and ends (${JSON.stringify([d.name, d.body, d.marker, d.pin, d.ends])})`,
    );
    const scale = await page.evaluate(() => window.__dofplan.scale());
    const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);
    // The slot on screen: along the rocker's line from O4 toward B (4 out),
    // from 0.9 to 3.1 out, measured from the markers' circles.
    const onRocker = async (what) => {
      const [o4, b, a] = await Promise.all(["rocker.O4", "rocker.B", "crank.A"].map((k) => markerPx(page, k)));
      const slot = await slotOf(page, "S");
      const u = [(b[0] - o4[0]) / dist(o4, b), (b[1] - o4[1]) / dist(o4, b)];
      const want = [0.9, 3.1].map((t) => [o4[0] + t * scale * u[0], o4[1] + t * scale * u[1]]);
      const off = Math.max(dist(slot.px[0], want[0]), dist(slot.px[1], want[1]));
      check(off < 0.02 && Math.abs(dist(o4, b) - 4 * scale) < 0.02, `${what}: the slot lies along the rocker's line O4 → B, from 0.9 to 3.1 out of O4 on screen (${off.toFixed(3)} px off)`);
      const pin = alongSegment(a, slot.px);
      const out = Math.hypot(...[0, 1].map((k) => slot.pin[k] - a[k]));
      check(pin.off < 0.5 && pin.t > 0 && pin.t < 1, `${what}: the crank's pin on the slot's centre line (${pin.off.toFixed(3)} px off), within its ends (${((0.9 + 2.2 * pin.t)).toFixed(4)} out of O4)`);
      check(out < 0.01, `${what}: the slot's pin drawn on crank.A (${out.toFixed(3)} px)`);
      return { slot, o4, b, a };
    };
    const drawn = await onRocker("as drawn");
    check(drawn.slot.body === "rocker" && drawn.slot.stroke === colourOf("rocker"), `the slot is the rocker's, in its colour (${drawn.slot.stroke})`);
    check(drawn.slot.together && drawn.slot.width >= 2 * drawn.slot.pinRadius, `its outline, channel and centre line share the segment; the channel fits the pin (${drawn.slot.width} px across, pin ${2 * drawn.slot.pinRadius} px)`);
    // The pin on top: the slots' layer over the bodies', the pin last in
    // its slot; with hit testing on, nothing is over it at its centre.
    const order = await page.evaluate(() => {
      const [bodies, slots] = [document.getElementById("bodies"), document.getElementById("slots")];
      const slot = slots.querySelector('[data-slot="S"]');
      const pin = slot.querySelector("circle.slot-pin");
      const after = Boolean(bodies.compareDocumentPosition(slots) & Node.DOCUMENT_POSITION_FOLLOWING);
      const last = Array.from(slot.querySelectorAll("line")).every((l) => Boolean(l.compareDocumentPosition(pin) & Node.DOCUMENT_POSITION_FOLLOWING));
      pin.style.pointerEvents = "auto";
      const r = pin.getBoundingClientRect();
      const top = document.elementFromPoint(r.x + r.width / 2, r.y + r.height / 2);
      pin.style.pointerEvents = "";
      return { after, last, top: top === pin, fill: getComputedStyle(pin).fill };
    });
    check(order.after && order.last && order.top, `the pin is drawn on top of the slot (slots over bodies: ${order.after}, pin after the slot's lines: ${order.last}, topmost at its centre: ${order.top}, fill ${order.fill})`);
    await page.screenshot({ path: join(SHOTS, "slots-quick-return-drawn.png") });

    // The crank at 90°: A = (0, 1), straight above O4 — the rocker, and
    // the slot with it, turned to the vertical.
    await setInput(page, "theta", 90);
    const s90 = await statusOf(page);
    check(s90.kind === "solved", `theta 90°: solved (${s90.text})`);
    const turned = await onRocker("theta 90°");
    const angle = screenAngle(turned.slot.px[0], turned.slot.px[1]);
    const drawnAngle = screenAngle(drawn.slot.px[0], drawn.slot.px[1]);
    check(between(angle, 90) < 0.01 && between(drawnAngle, (Math.atan2(2, 1) * 180) / Math.PI) < 0.01, `the slot turned with the rocker, from ${drawnAngle.toFixed(3)}° to the vertical (${angle.toFixed(3)}°)`);
    check(dist(turned.slot.from, [0, -2 + 0.9]) < 1e-9 && dist(turned.slot.to, [0, -2 + 3.1]) < 1e-9, `in the world its ends are (0, -1.1) and (0, 1.1) (${JSON.stringify(turned.slot.from)}, ${JSON.stringify(turned.slot.to)})`);
    await page.screenshot({ path: join(SHOTS, "slots-quick-return-90.png") });
    // Round the turn: the pin stays on the centre line, the slot on the
    // rocker's line.
    let worst = 0;
    for (let theta = 0; theta <= 360; theta += 30) {
      await setInput(page, "theta", theta);
      const [o4, b, a] = await Promise.all(["rocker.O4", "rocker.B", "crank.A"].map((k) => markerPx(page, k)));
      const slot = await slotOf(page, "S");
      const pin = alongSegment(a, slot.px);
      const rocker = alongSegment(o4, slot.px);
      worst = Math.max(worst, pin.off, rocker.off, alongSegment(b, slot.px).off, pin.t < 0 || pin.t > 1 ? Infinity : 0);
    }
    check(worst < 0.5, `a full turn in 30° steps: the pin on the slot's centre line within its ends, the slot on the rocker's line (worst ${worst.toFixed(3)} px)`);
    // A drag plans again from the pose on screen, the slot turned with the
    // rocker: the slider then moves it on, the pin on the slot.
    await setInput(page, "theta", 90);
    const errors0 = await page.evaluate(() => window.__dofplan.errors.length);
    const b90 = (await markers(page))["rocker.B"];
    const [bx, by] = await page.evaluate((p) => window.__dofplan.toPage(p), b90);
    await page.mouse.move(bx, by);
    await page.mouse.down();
    for (let i = 1; i <= 10; i++) {
      await page.mouse.move(bx - 4 * i, by);
      await page.waitForTimeout(5);
    }
    await settled(page);
    await page.mouse.up();
    await settled(page);
    const dragged = (await markers(page))["rocker.B"];
    check(dist(dragged, b90) > 0.1, `dragging the rocker's B moved it (${dist(dragged, b90).toFixed(3)})`);
    await setInput(page, "theta", 200);
    const s200 = await statusOf(page);
    await onRocker("after a drag, theta 200°");
    const errors = await page.evaluate((n) => window.__dofplan.errors.slice(n), errors0);
    check(s200.kind === "solved" && errors.length === 0, `the slider after the drag: solved, no error (${s200.kind}; ${errors.join("; ") || "none"})`);

    // The short slot: driven to 60° the pin would leave it at ≈ 23.13°.
    await page.selectOption("#open-file", "short_yoke.toml");
    await page.click("#open");
    await statusOf(page);
    const ydoc = await documentOf(page);
    check(ydoc.name === "short_yoke" && ydoc.slots.length === 1 && ydoc.slots[0].ends.join() === "-0.8,0.8", "short_yoke.toml: the scotch yoke, its slot's ends at ±0.8");
    // Opened, it is framed afresh: the box its motion and slot stay in
    // (the slot's ends reach past the yoke's markers) centred on the canvas.
    const [bx0, by0, bx1, by1] = ydoc.bounds;
    check(by0 === -0.8 && by1 === 0.8, `its bounds reach the slot's ends (${JSON.stringify(ydoc.bounds)})`);
    const centre = await page.evaluate((p) => window.__dofplan.project(p), [(bx0 + bx1) / 2, (by0 + by1) / 2]);
    const canvasBox = await page.$eval("#canvas", (c) => [c.getBoundingClientRect().width, c.getBoundingClientRect().height]);
    check(dist(centre, [canvasBox[0] / 2, canvasBox[1] / 2]) < 1, `framed afresh when opened: its bounds centred on the canvas (${centre.map((v) => v.toFixed(1))} against ${canvasBox.map((v) => (v / 2).toFixed(1))})`);
    const yokeSlot = async (what) => {
      const slot = await slotOf(page, "S");
      const p = alongSegment(await markerPx(page, "crank.P"), slot.px);
      const end = p.len * Math.max(0, p.t - 1, -p.t);
      check(p.off < 0.5 && end < 0.5, `${what}: the pin within the slot's segment on screen (${p.off.toFixed(3)} px off its line, ${end.toFixed(3)} px past an end; ${(p.t * 1.6 - 0.8).toFixed(4)} along it)`);
      return { slot, p };
    };
    const reach = Math.asin(0.8) * (180 / Math.PI) - 30;
    // Stepped there, as a slider is moved: every frame within the slot.
    for (let theta = 5; theta <= 60; theta += 5) {
      await page.$eval('input[data-input="theta"]', (e, v) => {
        e.value = String(v);
        e.dispatchEvent(new Event("input", { bubbles: true }));
      }, theta);
      await settled(page);
      const { p } = await yokeSlot(`theta ${theta}°`);
      if (p.t > 1 + 1e-6 || p.t < -1e-6) break;
    }
    const limited = await statusOf(page);
    check(limited.kind === "limited", `theta 60°: limited (${limited.kind})`);
    check(
      /step \d+ broke \(the pin would run past an end of its slot, gap [0-9.e-]+\): crank\.P within the slot of yoke\.S, from -0\.8 to 0\.8 along it/.test(limited.text),
      `the status names the break and the slot, as any limit's (${JSON.stringify(limited.text)})`,
    );
    const heldAt = (await probeInputs(page))[0];
    check(heldAt <= reach + 1e-6 && heldAt >= 20 - 1e-6, `held at the last pose within the slot, theta ${heldAt.toFixed(2)}° (the end is at ${reach.toFixed(2)}°)`);
    const shown = await page.$eval("#value-0", (e) => e.textContent);
    check(shown.includes("→"), `the slider shows the value asked and where the mechanism is (${shown})`);
    await yokeSlot("held at the limit");
    await page.screenshot({ path: join(SHOTS, "slots-scotch-yoke-limited.png") });
    // Search stops at the end itself.
    await page.selectOption("#policy", "search");
    await settled(page);
    const searched = await statusOf(page);
    check(searched.kind === "searched" && searched.text.includes("within the slot of yoke.S"), `search: stopped at the break point (${searched.kind}: ${JSON.stringify(searched.text)})`);
    const { p: atEnd } = await yokeSlot("searched");
    check(Math.abs(atEnd.t - 1) * atEnd.len < 0.5, `search: the pin at the slot's upper end (${((1 - atEnd.t) * atEnd.len).toFixed(3)} px short)`);
    await page.screenshot({ path: join(SHOTS, "slots-scotch-yoke-searched.png") });
    check(page.problems.length === 0, `no failed request or console error (${page.problems.join("; ") || "none"})`);
  } finally {
    child.kill();
    rmSync(dir, { recursive: true, force: true });
  }
}

/** An arc slot's drawing: its kind, its polylines (class, stroke, fill,
 * points on screen), its lines (none for an arc), its world ends
 * (data-from, data-to) and its pin's centre on screen. */
async function arcOf(page, name) {
  return page.$eval(`#slots [data-slot="${name}"]`, (g) => {
    const points = (l) => l.getAttribute("points").trim().split(/\s+/).map((xy) => xy.split(",").map(Number));
    const polylines = Array.from(g.querySelectorAll("polyline")).map((l) => ({
      class: ["slot-edge", "slot-channel", "slot-centre"].find((c) => l.classList.contains(c)),
      grabbable: l.classList.contains("grabbable"),
      stroke: l.getAttribute("stroke"),
      width: Number(l.getAttribute("stroke-width")),
      fill: getComputedStyle(l).fill,
      points: points(l),
    }));
    const pin = g.querySelector("circle.slot-pin");
    return {
      kind: g.dataset.slotKind,
      body: g.dataset.slotBody,
      polylines,
      lines: g.querySelectorAll("line").length,
      channel: polylines.find((l) => l.class === "slot-channel"),
      edge: polylines.find((l) => l.class === "slot-edge"),
      from: JSON.parse(g.dataset.from),
      to: JSON.parse(g.dataset.to),
      pin: [Number(pin.getAttribute("cx")), Number(pin.getAttribute("cy"))],
      pinRadius: Number(pin.getAttribute("r")),
    };
  });
}

// curved_lever in closed form (its header's): the pin's angle round the
// arc, degrees counter-clockwise from C's dir, at crank input `theta`.
function leverPinRound(theta) {
  const at = (t) => {
    const a = ((60 + t) * Math.PI) / 180;
    const p = [Math.cos(a), Math.sin(a)];
    const [dx, dy] = [4 - p[0], -p[1]];
    const d = Math.hypot(dx, dy);
    const along = (3.5 * 3.5 - 3 * 3 + d * d) / (2 * d);
    const h = Math.sqrt(3.5 * 3.5 - along * along);
    // C above the line from P to Q (to its left).
    const c = [p[0] + (along * dx - h * dy) / d, p[1] + (along * dy + h * dx) / d];
    return { p, c };
  };
  const deg = (v) => (Math.atan2(v[1], v[0]) * 180) / Math.PI;
  const drawn = at(0);
  const { p, c } = at(theta);
  const turned = deg([c[0] - 4, c[1]]) - deg([drawn.c[0] - 4, drawn.c[1]]);
  const round = deg([p[0] - c[0], p[1] - c[1]]) - deg([drawn.p[0] - drawn.c[0], drawn.p[1] - drawn.c[1]]) - turned;
  return ((((round + 180) % 360) + 360) % 360) - 180;
}

async function arcs(browser) {
  console.log("== mechanisms/slots/curved_lever.toml: an arc slot drawn round the lever's C and turning with it, the pin in it over a turn; its ends cut short, the pin held at an end");
  const dir = mkdtempSync(join(tmpdir(), "dofplan-edit-"));
  const lever = readFileSync(join(ROOT, "mechanisms/slots/curved_lever.toml"), "utf8");
  writeFileSync(join(dir, "curved_lever.toml"), lever);
  // The arc cut short: the pin, swinging to -33.4° round it, reaches the
  // end -20° between theta 50° and 55°.
  check(lever.includes("ends = [-40.0, 20.0]"), "curved_lever.toml's arc ends are [-40, 20], to cut short");
  writeFileSync(join(dir, "short_lever.toml"), lever.replace("ends = [-40.0, 20.0]", "ends = [-20.0, 20.0]").replace('name = "curved_lever"', 'name = "short_lever"'));
  const { child, page } = await openEditor(browser, "curved_lever.toml", dir);
  try {
    const doc = await documentOf(page);
    const colourOf = (body) => ["#2563eb", "#dc2626", "#059669", "#d97706", "#7c3aed", "#0891b2", "#db2777", "#65a30d"][doc.bodies.findIndex((b) => b.name === body) % 8];
    const names = await page.$$eval("[data-slot]", (els) => els.map((e) => e.dataset.slot));
    check(names.join() === "S", `one data-slot, S (${names})`);
    const d = doc.slots[0];
    check(
      JSON.stringify([d.name, d.body, d.marker, d.pin, d.ends, d.radius]) === JSON.stringify(["S", "lever", "lever.C", "crank.P", [-40, 20], 3.5]),
      `the document names the slot's body, marker, pin, ends and radius (${JSON.stringify([d.name, d.body, d.marker, d.pin, d.ends, d.radius])}; ${d.path.length} points on its path)`,
    );
    const drawn = await arcOf(page, "S");
    const classes = drawn.polylines.map((l) => l.class).join();
    check(
      drawn.kind === "arc" && drawn.lines === 0 && classes === "slot-edge,slot-channel,slot-centre",
      `kind ${drawn.kind}, drawn as polylines (${classes}; ${drawn.lines} lines)`,
    );
    check(
      drawn.body === "lever" && drawn.edge.stroke === colourOf("lever") && drawn.polylines.every((l) => l.fill === "none"),
      `the slot is the lever's, outlined in its colour (${drawn.edge.stroke}), its polylines unfilled (${drawn.polylines.map((l) => l.fill).join()})`,
    );
    check(drawn.edge.width > drawn.channel.width && drawn.channel.width >= 2 * drawn.pinRadius, `the channel fits the pin (${drawn.channel.width} px across, outline ${drawn.edge.width}, pin ${2 * drawn.pinRadius} px)`);
    // The view's scale, read again when a file is opened (framed afresh).
    let scale = await page.evaluate(() => window.__dofplan.scale());
    let radius = 3.5 * scale;
    const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);
    // Degrees counter-clockwise from `a0`, in (-180, 180].
    const from = (a, a0) => -((((a0 - a) % 360) + 540) % 360 - 180);
    // The arc on screen about the lever's C, the crank's pin in it.
    const inArc = async (what, theta = null) => {
      const [c, p] = await Promise.all(["lever.C", "crank.P"].map((k) => markerPx(page, k)));
      const slot = await arcOf(page, "S");
      const pts = slot.channel.points;
      const off = Math.max(...pts.map((q) => Math.abs(dist(q, c) - radius)));
      const angles = pts.map((q) => screenAngle(c, q));
      const steps = angles.slice(1).map((a, k) => from(a, angles[k]));
      const span = steps.reduce((x, y) => x + y, 0);
      const pinOff = Math.abs(dist(p, c) - radius);
      const round = from(screenAngle(c, p), angles[0]);
      const tolerance = (0.5 / radius) * (180 / Math.PI);
      const within = round >= -tolerance && round <= span + tolerance;
      const together = slot.polylines.every((l) => JSON.stringify(l.points) === JSON.stringify(pts));
      const world = (await markers(page))["lever.C"];
      const worldOff = Math.max(Math.abs(dist(slot.from, world) - 3.5), Math.abs(dist(slot.to, world) - 3.5));
      check(
        off < 0.05 && together && steps.every((s) => s > 0 && s <= 3.01) && Math.abs(span - 60) < 0.05 && worldOff < 1e-9,
        `${what}: every point of the channel ${(3.5).toFixed(1)} × ${scale.toFixed(2)} px from lever.C (worst ${off.toFixed(4)} px off, ${pts.length} points at most ${Math.max(...steps).toFixed(2)}° apart, counter-clockwise over ${span.toFixed(3)}°; its world ends ${worldOff.toExponential(1)} off the radius)`,
      );
      const expected = theta === null ? null : leverPinRound(theta);
      const agree = expected === null || Math.abs(-40 + round - expected) < tolerance;
      check(
        pinOff < 0.5 && within && agree && dist(slot.pin, p) < 0.01,
        `${what}: crank.P ${pinOff.toFixed(3)} px off the arc, ${(-40 + round).toFixed(3)}° round it${expected === null ? "" : ` (closed form ${expected.toFixed(3)}°)`}, within its ${span.toFixed(1)}° from -40°`,
      );
      return { slot, round, span, tolerance };
    };
    for (let theta = 0; theta <= 360; theta += 60) {
      await setInput(page, "theta", theta);
      const status = await statusOf(page);
      check(status.kind === "solved", `theta ${theta}°: solved (${status.kind})`);
      await inArc(`theta ${theta}°`, theta);
      if (theta === 0) await page.screenshot({ path: join(SHOTS, "arcs-curved-lever.png") });
      if (theta === 120) await page.screenshot({ path: join(SHOTS, "arcs-curved-lever-120.png") });
    }
    // Grabbing the arc grabs the lever: its outline is what is hit at its
    // middle, and a drag from there moves the lever, the pin kept in it.
    await setInput(page, "theta", 120);
    const mid = await page.$eval('#slots [data-slot="S"] polyline.slot-edge', (l) => {
      const pts = l.getAttribute("points").trim().split(/\s+/);
      const [x, y] = pts[Math.floor(pts.length / 2)].split(",").map(Number);
      const m = l.getScreenCTM();
      const at = [m.a * x + m.c * y + m.e, m.b * x + m.d * y + m.f];
      const hit = document.elementFromPoint(...at);
      return { at, hit: hit === l, grabbable: l.classList.contains("grabbable") };
    });
    check(mid.hit && mid.grabbable, `the arc's outline is what is under the pointer at its middle, grabbable (${mid.hit}, ${mid.grabbable})`);
    const c0 = (await markers(page))["lever.C"];
    const errors0 = await page.evaluate(() => window.__dofplan.errors.length);
    await page.mouse.move(...mid.at);
    await page.mouse.down();
    for (let i = 1; i <= 10; i++) {
      await page.mouse.move(mid.at[0] + 3 * i, mid.at[1] - 3 * i);
      await page.waitForTimeout(5);
    }
    await settled(page);
    await page.mouse.up();
    await settled(page);
    const c1 = (await markers(page))["lever.C"];
    const dragErrors = await page.evaluate((n) => window.__dofplan.errors.slice(n), errors0);
    check(dist(c0, c1) > 0.05 && dragErrors.length === 0, `dragging the arc moved the lever's C by ${dist(c0, c1).toFixed(3)} (errors: ${dragErrors.join("; ") || "none"})`);
    await inArc("after dragging the arc");

    // The short arc: driven to 180° the pin would leave it past -20°.
    await page.selectOption("#open-file", "short_lever.toml");
    await page.click("#open");
    await statusOf(page);
    const sdoc = await documentOf(page);
    scale = await page.evaluate(() => window.__dofplan.scale());
    radius = 3.5 * scale;
    check(sdoc.name === "short_lever" && sdoc.slots.length === 1 && sdoc.slots[0].ends.join() === "-20,20", `short_lever.toml: the curved lever, its arc's ends at -20° and 20° (${sdoc.slots[0].ends})`);
    let lo = 50;
    let hi = 55;
    while (hi - lo > 1e-9) {
      const mid = (lo + hi) / 2;
      if (leverPinRound(mid) > -20) lo = mid;
      else hi = mid;
    }
    const reach = lo;
    const shortArc = async (what) => {
      const [c, p] = await Promise.all(["lever.C", "crank.P"].map((k) => markerPx(page, k)));
      const slot = await arcOf(page, "S");
      const angles = slot.channel.points.map((q) => screenAngle(c, q));
      const span = angles.slice(1).reduce((x, a, k) => x + from(a, angles[k]), 0);
      const round = from(screenAngle(c, p), angles[0]);
      const past = radius * (Math.PI / 180) * Math.max(0, -round, round - span);
      const off = Math.abs(dist(p, c) - radius);
      check(off < 0.5 && past < 0.5, `${what}: the pin within the arc on screen (${off.toFixed(3)} px off it, ${past.toFixed(3)} px past an end; ${(-20 + round).toFixed(3)}° round it)`);
      return { round, span, past };
    };
    // Stepped there, as a slider is moved: every frame within the arc,
    // limited from the first step past the end on.
    let first = null;
    for (let theta = 5; theta <= 180; theta += 5) {
      await setInput(page, "theta", theta);
      const { past } = await shortArc(`theta ${theta}°`);
      if (past > 0) break;
      if (first === null && (await statusOf(page)).kind === "limited") first = theta;
    }
    const limited = await statusOf(page);
    check(limited.kind === "limited" && first === Math.ceil(reach / 5) * 5, `driven on to 180°: limited (${limited.kind}), from theta ${first}° on`);
    check(
      /the pin would run past an end of its slot/.test(limited.text) && limited.text.includes("crank.P within the arc slot about lever.C, from -20° to 20° round it"),
      `the status names the break and the arc slot (${JSON.stringify(limited.text)})`,
    );
    const heldAt = (await probeInputs(page))[0];
    check(heldAt <= reach + 1e-6 && heldAt >= 50 - 1e-6, `held at the last pose within the arc, theta ${heldAt.toFixed(2)}° (the end is at ${reach.toFixed(2)}°)`);
    await shortArc("held at the limit");
    await page.screenshot({ path: join(SHOTS, "arcs-short-lever-limited.png") });
    check(page.problems.length === 0, `no failed request or console error (${page.problems.join("; ") || "none"})`);
  } finally {
    child.kill();
    rmSync(dir, { recursive: true, force: true });
  }
}

/** The input values of the pose on screen (the frame's). */
async function probeInputs(page) {
  await settled(page);
  return page.evaluate(() => window.__dofplan.pose().inputs);
}

mkdirSync(SHOTS, { recursive: true });
const browser = await chromium.launch({
  executablePath: CHROMIUM,
  args: [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-default-apps",
    "--no-first-run",
  ],
});
const ONLY = process.env.ONLY ? process.env.ONLY.split(",") : null;
try {
  for (const scenario of [baseline, fourbar, openChain, pendulum, forces, limits, sliderCrank, empty, construct, files, broken, newFile, aids, numericRefused, gears, slots, arcs, spatial, stress]) {
    if (!ONLY || ONLY.includes(scenario.name)) await scenario(browser);
  }
  const problems = PAGES.flatMap(([file, page]) => page.problems.map((p) => `${file}: ${p}`));
  check(problems.length === 0, `no page had a failed request (no favicon 404) or a console error (${problems.join("; ") || "none"})`);
} catch (e) {
  check(false, `the test ran to the end (${e.stack ?? e})`);
} finally {
  await browser.close();
}
console.log(failures ? `${failures} check(s) failed` : "all checks passed");
console.log(`screenshots in ${SHOTS}`);
process.exit(failures ? 1 : 0);
