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
  for (const scenario of [baseline, fourbar, openChain, pendulum, forces, limits, sliderCrank, empty, construct, files, broken, newFile, aids, numericRefused, spatial, stress]) {
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
