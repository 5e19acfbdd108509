// dofplan edit: the page. It draws the mechanism the server sends, and
// sends back what the user does (slider values, sweep playback, drags, and
// edits of the mechanism); the server solves, or edits the file, and answers
// with the new pose or document. Nothing is solved or validated here: an
// edit the server refuses shows its message and changes nothing.
//
// Coordinates: the server speaks world coordinates (y up); the script maps
// them to screen pixels itself, so every drawn element's attributes are in
// pixels and each marker also carries its world position in data-x/data-y.

const SVG = "http://www.w3.org/2000/svg";
const COLOURS = ["#2563eb", "#dc2626", "#059669", "#d97706", "#7c3aed", "#0891b2", "#db2777", "#65a30d"];

const $ = (id) => document.getElementById(id);
const canvas = $("canvas");

// What the test reads: round trips of drag frames in milliseconds, from the
// pointer event to the animation frame after the new pose is in the DOM,
// and the same up to the DOM update alone.
const probe = { ready: false, frames: 0, latencies: [], domLatencies: [], serverMs: [], errors: [] };
window.__dofplan = probe;

let doc = null; // the `document` message
let markerIndex = []; // [{body, name, key}] in the server's marker order
let hulls = []; // per body: indices into markerIndex, in outline order
let pose = null; // the last `frame` message
let view = { s: 1, ox: 0, oy: 0 };
let userView = false; // zoomed or panned by the user: never refitted on its own
let values = []; // slider values, one per input
let grabbed = null; // {body, world} while dragging
let documentFor = null; // the type of request the last document answered
let shownFile = null; // the file the Open list last showed as the open one
// The drawing's elements, found once (a frame of a 50-body chain would
// otherwise spend its time in selector lookups).
let parts = { markers: [], shapes: [], ground: [], joints: [], bodies: new Map(), gears: [], slots: [] };

// The outbox: one request in flight at a time, and queued requests of one
// kind replaced by the newest (only the latest drag target or slider values
// matter), so a slow frame never builds a backlog.
let socket = null;
let nextId = 1;
let inFlight = null;
const outbox = [];

function enqueue(message, t0) {
  const last = outbox[outbox.length - 1];
  if (last && (message.type === "drag" || message.type === "inputs") && last.message.type === message.type) {
    // Keep the older pointer time: the latency counts from the first
    // pointer event this frame answers.
    last.message = message;
  } else {
    outbox.push({ message, t0 });
  }
  flush();
}

function flush() {
  if (inFlight || outbox.length === 0 || !socket || socket.readyState !== WebSocket.OPEN) return;
  const item = outbox.shift();
  item.message.id = nextId++;
  inFlight = item;
  socket.send(JSON.stringify(item.message));
}

function connect() {
  const scheme = location.protocol === "https:" ? "wss:" : "ws:";
  socket = new WebSocket(`${scheme}//${location.host}/ws${location.search}`);
  socket.addEventListener("open", () => setConnection("connected", "connected"));
  socket.addEventListener("close", () => {
    setConnection("closed", "disconnected: is `dofplan edit` still running?");
    inFlight = null;
  });
  socket.addEventListener("message", (event) => receive(JSON.parse(event.data)));
}

function setConnection(state, text) {
  const c = $("connection");
  c.dataset.state = state;
  c.textContent = text;
}

function receive(message) {
  const answered = inFlight && message.id === inFlight.message.id ? inFlight : null;
  if (answered) inFlight = null;
  if (message.type === "document") {
    // A document after the first one is an edit of the one on screen,
    // which keeps its view; an opened file is framed afresh (a document
    // carries no id: it answers the request in flight).
    const refit = !doc || (inFlight && inFlight.message.type === "open");
    // A document answers the request in flight (its frame, next, carries
    // the id): a text the user typed is kept unless that text was applied.
    documentFor = inFlight ? inFlight.message.type : null;
    setDocument(message);
    if (refit) fitView();
    else renderTraces();
  } else if (message.type === "frame") {
    setFrame(message, answered);
  } else if (message.type === "error") {
    probe.errors.push(message.message);
    if (answered && answered.message.type === "grab") refusedGrab();
    showStatus("error", message.message);
    if (answered && answered.message.type === "text") showFileErrors(message.message, placesIn(message.message));
    if (answered && answered.message.type === "open" && /unsaved changes/.test(message.message)) {
      // Asked again, the same file is opened and the changes dropped.
      openDiscard = answered.message.name;
    }
    draw();
  }
  if (answered && answered.message.type === "inputs" && playing) {
    requestAnimationFrame(playStep);
  }
  flush();
}

// ---- the document -------------------------------------------------------

function el(name, attributes = {}, parent = null) {
  const e = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attributes)) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}

function setDocument(d) {
  doc = d;
  forceScale = 0;
  // The last pose is of the document before: nothing is drawn until the
  // frame of this one, which the server sends next.
  pose = null;
  $("name").textContent = d.name;
  $("file").textContent = d.file;
  $("panel-plan").textContent = d.plan ?? `No plan: ${d.plan_error}`;
  $("panel-check").textContent = d.check;
  $("panel-rust").textContent = d.rust ?? `No module to emit: ${d.plan_error}`;
  markerIndex = [];
  d.bodies.forEach((b, bi) =>
    b.markers.forEach((m) => markerIndex.push({ body: bi, name: m.name, key: `${b.name}.${m.name}` })),
  );
  hulls = d.bodies.map((b, bi) => {
    const ids = markerIndex.map((m, i) => [m, i]).filter(([m]) => m.body === bi).map(([, i]) => i);
    const order = hull(ids.map((i) => markerAt(i).at));
    return order.map((k) => ids[k]);
  });
  buildInputs();
  buildDrawing();
  showEditing();
  showFile();
  showSweep();
  document.title = `${d.file}${d.editing && d.editing.dirty ? " (unsaved)" : ""} — dofplan edit`;
  if (d.broken) {
    // Nothing to draw: the file's text and what is wrong with it are.
    openTab("file");
    $("hint").textContent = "The file does not load, so there is nothing to draw: fix its text in the File tab and Apply.";
    showStatus("error", `${d.file} does not load: fix it in the File tab (its errors are marked there), then Apply.`);
  } else if (!is3d()) $("hint").textContent = HINTS[mode];
}

// The drawn position and direction of marker `i`.
function markerAt(i) {
  const m = markerIndex[i];
  return doc.bodies[m.body].markers.find((x) => x.name === m.name);
}

// Indices of the convex hull of `points`, counter-clockwise (monotone
// chain); every point when there are fewer than three.
function hull(points) {
  const idx = points.map((_, i) => i).sort((a, b) => points[a][0] - points[b][0] || points[a][1] - points[b][1]);
  if (idx.length < 3) return idx;
  const cross = (o, a, b) =>
    (points[a][0] - points[o][0]) * (points[b][1] - points[o][1]) -
    (points[a][1] - points[o][1]) * (points[b][0] - points[o][0]);
  const chain = (list) => {
    const out = [];
    for (const p of list) {
      while (out.length >= 2 && cross(out[out.length - 2], out[out.length - 1], p) <= 0) out.pop();
      out.push(p);
    }
    out.pop();
    return out;
  };
  const result = chain(idx).concat(chain(idx.slice().reverse()));
  return result.length >= 2 ? result : idx;
}

function buildInputs() {
  const box = $("inputs");
  box.replaceChildren();
  values = doc.inputs.map(() => 0);
  doc.inputs.forEach((input, k) => {
    const row = document.createElement("div");
    row.className = "input-row";
    const label = document.createElement("label");
    label.textContent = input.name;
    label.title = `${input.kind} at joint ${input.joint}`;
    const slider = document.createElement("input");
    slider.type = "range";
    slider.dataset.input = input.name;
    // The drawing is at 0: the range always holds it.
    slider.min = Math.min(input.min, 0);
    slider.max = Math.max(input.max, 0);
    slider.step = input.kind === "angle" ? 0.5 : (slider.max - slider.min) / 1000;
    slider.value = 0;
    slider.id = `input-${k}`;
    label.htmlFor = slider.id;
    const out = document.createElement("output");
    out.id = `value-${k}`;
    slider.addEventListener("input", () => {
      values[k] = Number(slider.value);
      stopPlaying();
      sendInputs();
    });
    const remove = document.createElement("button");
    remove.type = "button";
    remove.className = "remove-input";
    remove.dataset.removeInput = input.name;
    remove.title = `delete input ${input.name} (the joint stays)`;
    remove.textContent = "×";
    remove.addEventListener("click", () => sendEdits([{ op: "delete_input", input: input.name }]));
    row.append(label, slider, out, remove);
    box.appendChild(row);
  });
  showValues();
  const play = $("play");
  play.disabled = !(doc.sweep && doc.plan);
  play.title = doc.sweep ? "" : "the file has no [sweep]";
}

// Each slider's value, and where the mechanism is when that differs (held
// at a limit).
function showValues(reached = values) {
  doc.inputs.forEach((input, k) => {
    const unit = input.kind === "angle" ? "°" : "";
    const out = $(`value-${k}`);
    const at = reached[k] ?? values[k];
    out.textContent = `${values[k].toFixed(2)}${unit}`;
    out.title = "";
    if (Math.abs(at - values[k]) > 1e-9) {
      out.textContent += ` → ${at.toFixed(2)}${unit}`;
      out.title = "the value asked → where the mechanism is";
    }
  });
}

function sendInputs() {
  enqueue({ type: "inputs", values: values.slice(), policy: $("policy").value }, performance.now());
}

function buildDrawing() {
  for (const id of ["traces", "ground", "bodies", "slots", "gears", "joints"]) $(id).replaceChildren();
  parts = { markers: [], shapes: [], ground: [], joints: [], bodies: new Map(), gears: [], slots: [] };
  const index = new Map(markerIndex.map((m, i) => [m.key, i]));
  // A slot's marker and its pin are a joint's places too (the slot is
  // labelled, not its markers; a slot in the ground is hatched).
  const jointed = new Set([...doc.joints.flatMap((j) => j.markers), ...(doc.slots || []).flatMap((s) => [s.marker, s.pin])]);
  for (const key of Object.keys(doc.traces)) {
    el("path", { class: "trace", "data-trace": key }, $("traces"));
  }
  doc.bodies.forEach((b, bi) => {
    const g = el("g", { class: b.fixed ? "body fixed" : "body", "data-body": b.name }, $("bodies"));
    parts.bodies.set(b.name, g);
    const colour = COLOURS[bi % COLOURS.length];
    if (!b.fixed) {
      // In 3D the outline is found again each frame, from the projection.
      const outline = is3d() ? b.markers.length : hulls[bi].length;
      const shape = outline >= 3 ? "polygon" : "polyline";
      parts.shapes.push({ el: el(shape, { class: "link", stroke: colour, fill: colour }, g), body: bi });
    }
    markerIndex.forEach((m, i) => {
      if (m.body !== bi) return;
      const attributes = { class: b.fixed ? "marker ground-marker" : "marker", r: 3.5, "data-marker": m.key };
      const part = { el: el("circle", attributes, g), i };
      // A joint's label names its markers' place; a marker no joint uses
      // (a coupler point) is named itself, on a small linkage.
      if (!jointed.has(m.key) && doc.joints.length <= 12 && !b.fixed) {
        part.label = el("text", { class: "marker-label" }, g);
        part.label.textContent = m.key;
      }
      parts.markers.push(part);
    });
    if (!b.fixed) {
      g.addEventListener("pointerdown", (event) => {
        if (mode === "move" && !panning && !spaceHeld && !is3d()) grab(event, b.name);
      });
    }
  });
  // Ground hatching under every ground marker a joint uses (or every
  // ground marker, when none is jointed yet).
  // (Hatching is a planar drawing's: a spatial ground has no "below".)
  const fixedMarkers = is3d() ? [] : markerIndex.map((m, i) => [m, i]).filter(([m]) => doc.bodies[m.body].fixed);
  const anchors = fixedMarkers.filter(([m]) => jointed.has(m.key));
  for (const [m, i] of anchors.length ? anchors : fixedMarkers) {
    const g = el("g", { class: "ground-anchor", "data-ground": m.key }, $("ground"));
    const rect = el("rect", { class: "ground-hatch", width: 32, height: 10 }, g);
    parts.ground.push({ rect, line: el("line", { class: "ground-base" }, g), i });
  }
  // A spatial ground: a mark (the planar pivot's triangle and hatching)
  // under each of its markers, as the CLI's views draw it.
  parts.marks = [];
  if (is3d()) {
    markerIndex.forEach((m, i) => {
      if (!doc.bodies[m.body].fixed) return;
      const g = el("g", { class: "ground-mark", "data-ground": m.key }, $("ground"));
      el("polygon", { points: "0,0 -7,12 7,12" }, g);
      el("path", { d: "M-11 12H11M-3.5 12L-8 17M1.5 12L-3 17M6.5 12L2 17M11.5 12L7 17" }, g);
      parts.marks.push({ g, i });
    });
  }
  for (const j of doc.joints) {
    const g = el("g", { class: `joint ${j.kind}`, "data-joint": j.name }, $("joints"));
    const [a, b] = j.markers.map((k) => index.get(k));
    const part = { joint: j, a, b, k: parts.joints.length };
    // A spatial joint's axis, through its pin (drawn when the frame has it).
    if (is3d()) part.axis = el("line", { class: "joint-axis", visibility: "hidden" }, g);
    if (j.kind !== "prismatic" || is3d()) {
      // A pin; in 3D every kind is drawn as one, named by its class.
      part.circle = el("circle", { r: 6 }, g);
    } else {
      part.line = el("line", {}, g);
      part.rect = el("rect", { width: 26, height: 14, rx: 2 }, g);
    }
    // Names help on a small linkage and only clutter a long chain.
    if (doc.joints.length <= 12) {
      part.label = el("text", { class: "joint-label" }, g);
      part.label.textContent = j.name;
    }
    parts.joints.push(part);
  }
  buildSlots(index);
  buildGears();
  el("circle", { class: "grab-point", r: 4.5, visibility: "hidden", id: "grab-point" }, canvas);
  markSelection();
}

// ---- pins in slots ------------------------------------------------------------
// Each slot is drawn along its segment (its ends in the slotted body's
// drawn coordinates, as the document gives them) and moves with that
// body's pose: a channel a pin's width across with rounded ends, outlined
// in the body's colour, over the bodies. An arc slot (one with a radius)
// is drawn the same way along its path, the points of its centre line the
// document gives, as polylines. The pin, drawn as its marker under the
// bodies, is drawn again on top of the slot as a joint's pin, where the
// pin's marker is. Grabbing the slot grabs its body.

// The slot's channel and the pin across it, in pixels: the pin fits it.
const SLOT_HALF_WIDTH = 6;
const SLOT_PIN_RADIUS = 4.5;

function buildSlots(index) {
  if (is3d()) return;
  const bodyIndex = new Map(doc.bodies.map((b, i) => [b.name, i]));
  const labelled = doc.joints.length + (doc.slots || []).length <= 12;
  for (const slot of doc.slots || []) {
    const body = bodyIndex.get(slot.body);
    const colour = COLOURS[body % COLOURS.length];
    const arc = slot.radius != null;
    const group = el("g", { class: "slot", "data-slot": slot.name, "data-slot-body": slot.body, "data-slot-kind": arc ? "arc" : "straight" }, $("slots"));
    // A straight slot's lines; an arc's polylines, unfilled, their caps and
    // joins round (the page's style rounds only lines' caps).
    const [shape, style] = arc
      ? ["polyline", { fill: "none", "stroke-linecap": "round", "stroke-linejoin": "round", "pointer-events": "none" }]
      : ["line", {}];
    const part = {
      body,
      segment: slot.segment,
      path: arc ? slot.path : null,
      pin: index.get(slot.pin),
      group,
      edge: el(shape, { class: "slot-edge", ...style, stroke: colour, "stroke-width": 2 * SLOT_HALF_WIDTH + 4 }, group),
      channel: el(shape, { class: "slot-channel", ...style, "stroke-width": 2 * SLOT_HALF_WIDTH }, group),
      centre: el(shape, { class: "slot-centre", ...style, stroke: colour }, group),
      pinCircle: el("circle", { class: "slot-pin", r: SLOT_PIN_RADIUS, "data-slot-pin": slot.pin }, group),
    };
    if (labelled) {
      part.label = el("text", { class: "joint-label slot-label" }, group);
      part.label.textContent = slot.name;
    }
    if (!doc.bodies[body].fixed) {
      part.edge.classList.add("grabbable");
      part.edge.addEventListener("pointerdown", (event) => {
        if (mode === "move" && !panning && !spaceHeld) grab(event, slot.body);
      });
    }
    parts.slots.push(part);
  }
}

function drawSlots(screen) {
  const f = (v) => v.toFixed(2);
  for (const { body, segment, path, pin, group, edge, channel, centre, pinCircle, label } of parts.slots) {
    const world = placer(body);
    const [a, b] = segment.map(world);
    if (path) {
      const points = path.map((c) => toScreen(world(c)).map(f).join(",")).join(" ");
      for (const line of [edge, channel, centre]) line.setAttribute("points", points);
    } else {
      const [p, q] = [a, b].map(toScreen);
      for (const line of [edge, channel, centre]) {
        for (const [k, v] of Object.entries({ x1: p[0], y1: p[1], x2: q[0], y2: q[1] })) line.setAttribute(k, f(v));
      }
    }
    group.dataset.from = JSON.stringify(a);
    group.dataset.to = JSON.stringify(b);
    const [x, y] = screen[pin];
    pinCircle.setAttribute("cx", f(x));
    pinCircle.setAttribute("cy", f(y));
    if (label) {
      label.setAttribute("x", f(x + 9));
      label.setAttribute("y", f(y - 9));
    }
  }
}

// ---- gear pairs and racks ---------------------------------------------------
// Each pitch circle is drawn about its body's pivot (where the document
// says it is in the body's coordinates, which are the drawing's) and moves
// with the body's pose, with a tick that turns with it: toward the point
// where the pair touched as drawn (a spoke from the pivot; a ring's tick
// outside its rim). A rack's pitch line slides with the rack, its tick
// marks a twelfth of its pinion's turn apart (the one at the drawn pitch
// point longer). In the bodies' colours; grabbing one grabs its body.

const along = (p, t, u) => [p[0] + t * u[0], p[1] + t * u[1]];
function unit(v) {
  const n = Math.hypot(v[0], v[1]);
  return n > 0 ? [v[0] / n, v[1] / n] : [1, 0];
}

function buildGears() {
  if (is3d()) return;
  const bodyIndex = new Map(doc.bodies.map((b, i) => [b.name, i]));
  for (const gear of doc.gears || []) {
    const group = el("g", { class: `gear ${gear.kind}`, "data-gear": gear.name }, $("gears"));
    const bodies = gear.bodies.map((name) => bodyIndex.get(name));
    const colour = (k) => COLOURS[bodies[k] % COLOURS.length];
    const radii = gear.kind === "gear" ? gear.radii : [gear.radius];
    const circles = radii.map((r, k) => {
      const centre = gear.centres[k];
      const ring = gear.kind === "gear" && gear.internal && r > radii[1 - k];
      const u = unit([gear.pitch[0] - centre[0], gear.pitch[1] - centre[1]]);
      const [t0, t1] = ring ? [r, 1.1 * r] : [0, r];
      const attributes = { class: ring ? "pitch ring" : "pitch", stroke: colour(k), "data-gear-body": gear.bodies[k] };
      return {
        el: el("circle", attributes, group),
        tick: el("line", { class: "gear-tick", stroke: colour(k), "data-gear-body": gear.bodies[k] }, group),
        body: bodies[k],
        centre,
        r,
        ends: [along(centre, t0, u), along(centre, t1, u)],
      };
    });
    let rack = null;
    if (gear.line) {
      // The line and its ticks in the rack's coordinates, moved as one.
      const { at, dir, from, to, normal, step } = gear.line;
      const ticks = [];
      for (let k = Math.ceil(from / step); k <= Math.floor(to / step); k++) {
        const p = along(at, k * step, dir);
        ticks.push([p, along(p, (k === 0 ? 0.3 : 0.15) * gear.radius, normal)]);
      }
      rack = {
        body: bodies[1],
        ends: [along(at, from, dir), along(at, to, dir)],
        ticks,
        line: el("line", { class: "rack-pitch", stroke: colour(1), "data-gear-body": gear.bodies[1] }, group),
        marks: el("path", { class: "rack-ticks", stroke: colour(1), "data-gear-body": gear.bodies[1] }, group),
      };
    }
    for (const part of [...circles.map((c) => c.el), rack && rack.line].filter(Boolean)) {
      const name = part.dataset.gearBody;
      if (doc.bodies[bodyIndex.get(name)].fixed) continue;
      part.classList.add("grabbable");
      part.addEventListener("pointerdown", (event) => {
        if (mode === "move" && !panning && !spaceHeld) grab(event, name);
      });
    }
    parts.gears.push({ circles, rack });
  }
}

// Body `bi`'s pose on screen, as a map of its (drawn) points to the world.
function placer(bi) {
  const [c, s, x, y] = pose.poses[bi];
  return (p) => [c * p[0] - s * p[1] + x, s * p[0] + c * p[1] + y];
}

function drawGears() {
  const f = (v) => v.toFixed(2);
  for (const { circles, rack } of parts.gears) {
    for (const c of circles) {
      const world = placer(c.body);
      const at = world(c.centre);
      const [x, y] = toScreen(at);
      c.el.setAttribute("cx", f(x));
      c.el.setAttribute("cy", f(y));
      c.el.setAttribute("r", f(c.r * view.s));
      c.el.dataset.x = String(at[0]);
      c.el.dataset.y = String(at[1]);
      c.el.dataset.r = String(c.r);
      const [p, q] = c.ends.map((e) => toScreen(world(e)));
      for (const [k, v] of Object.entries({ x1: p[0], y1: p[1], x2: q[0], y2: q[1] })) c.tick.setAttribute(k, f(v));
    }
    if (rack) {
      const world = placer(rack.body);
      const [a, b] = rack.ends.map(world);
      const [p, q] = [a, b].map(toScreen);
      for (const [k, v] of Object.entries({ x1: p[0], y1: p[1], x2: q[0], y2: q[1] })) rack.line.setAttribute(k, f(v));
      rack.line.dataset.from = JSON.stringify(a);
      rack.line.dataset.to = JSON.stringify(b);
      const d = rack.ticks.map(([u, v]) => {
        const [[ux, uy], [vx, vy]] = [toScreen(world(u)), toScreen(world(v))];
        return `M${f(ux)},${f(uy)}L${f(vx)},${f(vy)}`;
      });
      rack.marks.setAttribute("d", d.join(""));
    }
  }
}

// ---- view -----------------------------------------------------------------

// The grid: off until toggled (G). When on, it is drawn under the
// mechanism and every point placed by the pointer (a body's points, a new
// marker, a marker dropped off every other marker) snaps to it.
let gridOn = false;

// The grid's spacing in world units: 1, 2 or 5 times a power of ten, the
// smallest at least 24 pixels apart at this zoom.
function gridStep() {
  const want = 24 / view.s;
  const power = 10 ** Math.floor(Math.log10(want));
  for (const k of [1, 2, 5, 10]) if (k * power >= want) return k * power;
  return 10 * power;
}

// `p` on the nearest grid point when the grid is on (the numbers rounded
// to the grid's decimals, so 0.30000000000000004 is written 0.3).
function snapped(p) {
  if (!gridOn || is3d()) return p;
  const step = gridStep();
  const decimals = Math.max(0, -Math.floor(Math.log10(step)) + 1);
  return p.map((v) => Number((Math.round(v / step) * step).toFixed(decimals)));
}

function drawGrid() {
  const g = $("grid");
  g.replaceChildren();
  if (!gridOn || !doc || is3d()) return;
  const rect = canvas.getBoundingClientRect();
  const step = gridStep();
  const [x0, x1] = [(0 - view.ox) / view.s, (rect.width - view.ox) / view.s];
  const [y0, y1] = [(view.oy - rect.height) / view.s, view.oy / view.s];
  const line = (k, vertical) => {
    const v = k * step;
    const major = k % 5 === 0;
    const cls = k === 0 ? "axis-line" : major ? "major" : "";
    if (vertical) el("line", { class: cls, x1: sx(v).toFixed(1), x2: sx(v).toFixed(1), y1: 0, y2: rect.height }, g);
    else el("line", { class: cls, y1: sy(v).toFixed(1), y2: sy(v).toFixed(1), x1: 0, x2: rect.width }, g);
  };
  for (let k = Math.ceil(x0 / step); k <= Math.floor(x1 / step); k++) line(k, true);
  for (let k = Math.ceil(y0 / step); k <= Math.floor(y1 / step); k++) line(k, false);
  g.dataset.step = String(step);
}

// ---- forces -------------------------------------------------------------
// A file with loads sends with each frame what holds its pose still: each
// joint's reaction (the force its first body exerts on its second) and
// each input's force or torque. Shown on request, as arrows at the
// joints' second markers, one scale for a document (the largest force
// seen so far is a fifth of the mechanism's size), so that an arrow
// growing over a sweep is a force growing.
let forcesOn = false;
let forceScale = 0;

function setForces(on) {
  forcesOn = on;
  $("forces-toggle").setAttribute("aria-pressed", String(on));
  drawForces();
}
$("forces-toggle").addEventListener("click", () => setForces(!forcesOn));

const shortNumber = (v) => (Math.abs(v) >= 1e4 || (Math.abs(v) < 1e-2 && v !== 0) ? v.toExponential(2) : v.toPrecision(4).replace(/\.?0+$/, ""));

function drawForces() {
  const g = $("forces");
  g.replaceChildren();
  const f = pose && pose.forces;
  $("forces-toggle").hidden = !f;
  if (!forcesOn || !f) return;
  const size = (v) => Math.hypot(...v);
  for (const r of f.reactions) forceScale = Math.max(forceScale, size(r));
  if (!(forceScale > 0)) return;
  // World length per unit force: the largest force seen is a fifth of the
  // mechanism's size (in space the arrow is that vector, projected).
  const perForce = (0.2 * (doc.size || 1)) / forceScale;
  for (const { joint, b, k } of parts.joints) {
    const force = f.reactions[k];
    const at = pose.markers[b];
    const [x, y] = toScreen(at);
    const a = el("g", { class: "force", "data-force": joint.name }, g);
    a.dataset.vector = JSON.stringify(force);
    const [tx, ty] = toScreen(at.map((c, i) => c + force[i] * perForce));
    if (Math.hypot(tx - x, ty - y) < 2) continue;
    el("line", { class: "reaction", x1: x.toFixed(2), y1: y.toFixed(2), x2: tx.toFixed(2), y2: ty.toFixed(2), "marker-end": "url(#force-head)" }, a);
    const label = el("text", { class: "force-value", x: (tx + 4).toFixed(2), y: (ty - 4).toFixed(2) }, a);
    label.textContent = `${joint.name} ${shortNumber(size(force))}`;
  }
  doc.inputs.forEach((input, k) => {
    const part = parts.joints.find((p) => p.joint.name === input.joint);
    if (!part) return;
    const q = f.inputs[k];
    const [x, y] = toScreen(pose.markers[part.b]);
    const a = el("g", { class: "input-force", "data-input-force": input.name }, g);
    a.dataset.value = String(q);
    if (input.kind === "angle") {
      // A torque: an arc around the pin, its head turning the way the
      // driver turns the input's second body (counter-clockwise positive
      // in the plane; in space about the joint's axis, drawn on screen).
      const r = 18;
      const [from, to] = q >= 0 ? [-0.6, 1.9] : [1.9, -0.6];
      const p = (t) => [x + r * Math.cos(t), y - r * Math.sin(t)];
      const [p0, p1] = [p(from), p(to)];
      el("path", { class: "input-torque", d: `M${p0[0].toFixed(2)},${p0[1].toFixed(2)} A${r},${r} 0 0 ${q >= 0 ? 0 : 1} ${p1[0].toFixed(2)},${p1[1].toFixed(2)}`, "marker-end": "url(#force-head)" }, a);
    }
    const label = el("text", { class: "force-value", x: (x - 10).toFixed(2), y: (y + 32).toFixed(2) }, a);
    label.textContent = `${input.name} ${shortNumber(q)} (${input.kind === "angle" ? "torque" : "force"})`;
  });
  const notes = [];
  if (!f.held) notes.push("the inputs cannot hold this pose: least-squares forces");
  // An over-constrained mechanism: the redundant joints' shares are the
  // least-norm ones, one of many.
  if (f.indeterminate.length) notes.push(`not unique (redundant joints): ${f.indeterminate.join(", ")}`);
  // Low on the canvas, clear of the toolbar over its top and of the
  // axes in its lower left corner.
  const bottom = (canvas.clientHeight || 600) - 120;
  notes.forEach((text, i) => {
    const note = el("text", { class: "not-held", x: 12, y: bottom - 16 * (notes.length - 1 - i) }, g);
    note.textContent = text;
  });
}

function setGrid(on) {
  gridOn = on;
  $("grid-toggle").setAttribute("aria-pressed", String(on));
  drawGrid();
}
$("grid-toggle").addEventListener("click", () => setGrid(!gridOn));

function fitView() {
  if (!doc) return;
  // The whole motion of the sweep, and the pose on screen.
  const world = [];
  if (is3d()) {
    // The corners of the box the sweep stays in, as projected.
    const [x0, y0, z0, x1, y1, z1] = doc.bounds;
    for (const x of [x0, x1]) for (const y of [y0, y1]) for (const z of [z0, z1]) world.push([x, y, z]);
  } else {
    const [bx0, by0, bx1, by1] = doc.bounds;
    world.push([bx0, by0], [bx1, by1]);
  }
  for (const path of Object.values(doc.traces)) world.push(...path);
  if (pose) world.push(...pose.markers);
  const points = world.filter((p) => p.every(Number.isFinite)).map(project);
  let [x0, y0, x1, y1] = [Infinity, Infinity, -Infinity, -Infinity];
  for (const [x, y] of points) {
    x0 = Math.min(x0, x);
    y0 = Math.min(y0, y);
    x1 = Math.max(x1, x);
    y1 = Math.max(y1, y);
  }
  // A drawing of one point (a new document) is shown ten units wide.
  if (x1 - x0 < 1e-9 && y1 - y0 < 1e-9) {
    x0 -= 5;
    x1 += 5;
    y0 -= 5;
    y1 += 5;
  }
  const size = doc.size || 1;
  const pad = 0.25 * size;
  x0 -= pad;
  x1 += pad;
  y0 -= pad;
  y1 += pad;
  const rect = canvas.getBoundingClientRect();
  const s = Math.min(rect.width / (x1 - x0), rect.height / (y1 - y0));
  view = { s, ox: rect.width / 2 - s * (x0 + x1) / 2, oy: rect.height / 2 + s * (y0 + y1) / 2 };
  userView = false;
  renderTraces();
}

// The traces in screen pixels, after the view or the document changed.
function renderTraces() {
  if (!doc) return;
  for (const [key, path] of Object.entries(doc.traces)) {
    const d = path
      .map((p, k) => {
        const [x, y] = toScreen(p);
        return `${k ? "L" : "M"}${x.toFixed(1)},${y.toFixed(1)}`;
      })
      .join("");
    canvas.querySelector(`path[data-trace="${CSS.escape(key)}"]`).setAttribute("d", d);
  }
  drawGrid();
  drawFloor();
  draw();
}

// The floor of a spatial view: a grid on the plane under the lowest point
// the sweep reaches, over the box it stays in, so depth reads at a glance.
function drawFloor() {
  const g = $("floor");
  g.replaceChildren();
  if (!doc || !is3d()) return;
  const [x0, y0, z0, x1, y1] = doc.bounds;
  if (![x0, y0, z0, x1, y1].every(Number.isFinite)) return;
  const size = doc.size || Math.max(x1 - x0, y1 - y0, 1);
  const want = size / 6;
  const power = 10 ** Math.floor(Math.log10(want));
  const step = [1, 2, 5, 10].map((k) => k * power).find((v) => v >= want);
  const [a0, a1] = [Math.floor((x0 - 0.25 * size) / step), Math.ceil((x1 + 0.25 * size) / step)];
  const [b0, b1] = [Math.floor((y0 - 0.25 * size) / step), Math.ceil((y1 + 0.25 * size) / step)];
  const line = (p, q) => {
    const [[px, py], [qx, qy]] = [toScreen(p), toScreen(q)];
    el("line", { class: "floor-line", x1: px.toFixed(1), y1: py.toFixed(1), x2: qx.toFixed(1), y2: qy.toFixed(1) }, g);
  };
  for (let a = a0; a <= a1; a++) line([a * step, b0 * step, z0], [a * step, b1 * step, z0]);
  for (let b = b0; b <= b1; b++) line([a0 * step, b * step, z0], [a1 * step, b * step, z0]);
  g.dataset.step = String(step);
  g.dataset.z = String(z0);
}

function inView(points) {
  const rect = canvas.getBoundingClientRect();
  return points.map(toScreen).every(([x, y]) => x >= 0 && x <= rect.width && y >= 0 && y <= rect.height);
}

// The view of a spatial document: turned `yaw` about the world z axis,
// then tilted `pitch` toward it (90°: seen from above, along -z).
const camera = { yaw: (-30 * Math.PI) / 180, pitch: (55 * Math.PI) / 180 };
const is3d = () => Boolean(doc && doc.dimension === 3);

// A world point in the plane of the screen (before scaling): a planar
// point as it is, a spatial one as the camera sees it.
function project(p) {
  if (!is3d()) return [p[0], p[1]];
  const [c, s] = [Math.cos(camera.yaw), Math.sin(camera.yaw)];
  const [x1, y1] = [c * p[0] - s * p[1], s * p[0] + c * p[1]];
  return [x1, y1 * Math.sin(camera.pitch) + p[2] * Math.cos(camera.pitch)];
}

function toScreen(p) {
  const [u, v] = project(p);
  return [sx(u), sy(v)];
}

const sx = (x) => view.ox + view.s * x;
const sy = (y) => view.oy - view.s * y;

function toWorld(event) {
  const rect = canvas.getBoundingClientRect();
  return [(event.clientX - rect.left - view.ox) / view.s, (view.oy - (event.clientY - rect.top)) / view.s];
}

// ---- a frame ----------------------------------------------------------------

function setFrame(frame, answered) {
  const first = !pose;
  pose = frame;
  // The first pose of a document: the selection's controls can show it.
  if (first) markSelection();
  // Sliders keep what was asked of them (a limit shows beside it); a drag
  // moves the inputs, and the sliders follow.
  const asked = answered && answered.message.type === "inputs";
  if (!asked && frame.inputs.length === values.length && !sliderHeld) {
    values = frame.inputs.slice();
    canvasInputs().forEach((slider, k) => {
      slider.value = values[k];
    });
  }
  showValues(frame.inputs);
  // The selected marker's coordinates and link's lengths follow the pose.
  if (selection && selection.kind !== "joint") showNumeric(Boolean(doc.editing && doc.editing.editable));
  // A pose that has left the view is brought back into it, but never
  // while dragging: the view would slide under the pointer.
  if (!grabbed && !userView && !inView(frame.markers)) fitView();
  draw();
  // A file that does not load has no motion to report: its status is
  // what is wrong with it (or what its fix so far did).
  if (frame.edited !== undefined) showStatus(doc.broken ? "error" : "edited", frame.edited);
  else if (!doc.broken) showFrameStatus(frame);
  probe.frames++;
  if (answered && answered.message.type === "grab") probe.grabMs = frame.server_ms;
  if (answered && answered.message.type === "drag") {
    const t0 = answered.t0;
    probe.domLatencies.push(performance.now() - t0);
    probe.serverMs.push(frame.server_ms);
    requestAnimationFrame(() => probe.latencies.push(performance.now() - t0));
  }
  probe.ready = true;
}

function canvasInputs() {
  return Array.from(document.querySelectorAll("input[data-input]"));
}

// A slider the user is holding is not moved under the pointer.
let sliderHeld = false;
document.addEventListener("pointerdown", (e) => {
  if (e.target.matches && e.target.matches("input[data-input]")) sliderHeld = true;
});
document.addEventListener("pointerup", () => {
  sliderHeld = false;
});

function draw() {
  if (!doc || !pose) return;
  const world = pose.markers;
  const screen = world.map(toScreen);
  for (const { el: c, i, label } of parts.markers) {
    c.setAttribute("cx", screen[i][0].toFixed(2));
    c.setAttribute("cy", screen[i][1].toFixed(2));
    if (label) {
      label.setAttribute("x", (screen[i][0] + 7).toFixed(2));
      label.setAttribute("y", (screen[i][1] - 7).toFixed(2));
    }
    c.dataset.x = String(world[i][0]);
    c.dataset.y = String(world[i][1]);
    if (world[i].length === 3) c.dataset.z = String(world[i][2]);
  }
  for (const { el: shape, body } of parts.shapes) {
    let outline = hulls[body];
    if (is3d()) {
      const ids = markerIndex.map((m, i) => [m, i]).filter(([m]) => m.body === body).map(([, i]) => i);
      outline = hull(ids.map((i) => screen[i])).map((k) => ids[k]);
    }
    const points = outline.map((i) => `${screen[i][0].toFixed(2)},${screen[i][1].toFixed(2)}`);
    // A one-marker body is a dot: a polyline needs two points.
    if (points.length === 1) points.push(points[0]);
    shape.setAttribute("points", points.join(" "));
  }
  for (const { rect, line, i } of parts.ground) {
    const [x, y] = screen[i];
    rect.setAttribute("x", (x - 16).toFixed(2));
    rect.setAttribute("y", (y + 7).toFixed(2));
    for (const [k, v] of Object.entries({ x1: x - 18, x2: x + 18, y1: y + 7, y2: y + 7 })) line.setAttribute(k, v.toFixed(2));
  }
  for (const { g, i } of parts.marks || []) {
    g.setAttribute("transform", `translate(${screen[i][0].toFixed(2)} ${screen[i][1].toFixed(2)})`);
  }
  for (const { joint, a, b, k, label, circle, rect, line, axis } of parts.joints) {
    const [x, y] = screen[b];
    if (axis) {
      const dir = pose.axes && pose.axes[k];
      axis.setAttribute("visibility", dir ? "visible" : "hidden");
      if (dir) {
        const r = 0.18 * (doc.size || 1);
        const at = world[b];
        const [p, q] = [-r, r].map((t) => toScreen([at[0] + t * dir[0], at[1] + t * dir[1], at[2] + t * dir[2]]));
        for (const [name, v] of Object.entries({ x1: p[0], y1: p[1], x2: q[0], y2: q[1] })) axis.setAttribute(name, v.toFixed(2));
      }
    }
    if (label) {
      label.setAttribute("x", (x + 9).toFixed(2));
      label.setAttribute("y", (y - 9).toFixed(2));
    }
    if (circle) {
      circle.setAttribute("cx", x.toFixed(2));
      circle.setAttribute("cy", y.toFixed(2));
      continue;
    }
    // A prismatic joint: a block on the second marker, sliding along the
    // first marker's direction (turned with its body), and its slot.
    const dir = markerAt(a).dir || [1, 0];
    const [c, s] = pose.poses[markerIndex[a].body];
    const [dx, dy] = [c * dir[0] - s * dir[1], s * dir[0] + c * dir[1]];
    const degrees = (-Math.atan2(dy, dx) * 180) / Math.PI;
    rect.setAttribute("x", (x - 13).toFixed(2));
    rect.setAttribute("y", (y - 7).toFixed(2));
    rect.setAttribute("transform", `rotate(${degrees.toFixed(3)} ${x.toFixed(2)} ${y.toFixed(2)})`);
    const reach = 0.6 * doc.size * view.s;
    const [ax, ay] = screen[a];
    line.setAttribute("x1", (ax - reach * dx).toFixed(2));
    line.setAttribute("y1", (ay + reach * dy).toFixed(2));
    line.setAttribute("x2", (ax + reach * dx).toFixed(2));
    line.setAttribute("y2", (ay - reach * dy).toFixed(2));
  }
  drawSlots(screen);
  drawGears();
  drawPreview();
  drawAxes();
  drawForces();
  if (grabbed) {
    const p = grabbed.world;
    const dot = $("grab-point");
    dot.setAttribute("cx", sx(p[0]).toFixed(2));
    dot.setAttribute("cy", sy(p[1]).toFixed(2));
  }
}

function showFrameStatus(frame) {
  const d = frame.detail;
  let text = frame.status;
  if (d && (frame.status === "limited" || frame.status === "searched")) {
    const held = frame.status === "limited" ? "held at the last pose that closed" : "stopped at the break point";
    text = `${frame.status}: ${held}\nstep ${d.step} broke (${d.reason}, gap ${d.gap.toPrecision(3)}): ${d.explanation}`;
  } else if (d && frame.status === "stretched" && grabbed) {
    // A drag relaxes only the drag itself: its "step" is the drag.
    text = `stretched: ${d.reason}, ${d.residual.toPrecision(3)} away\n${d.explanation}`;
  } else if (d && frame.status === "stretched") {
    text = `stretched: ${d.reason} (residual ${d.residual.toPrecision(3)})\nstep ${d.step}: ${d.explanation}`;
  }
  showStatus(frame.status, text);
}

function showStatus(kind, text) {
  const s = $("status");
  s.dataset.status = kind;
  s.textContent = text;
}

// ---- dragging ----------------------------------------------------------------

function grab(event, body) {
  if (event.button !== 0 || !pose) return;
  event.preventDefault();
  stopPlaying();
  const at = toWorld(event);
  // The grabbed point on the body, kept to show where the pointer holds it.
  grabbed = { body, world: at };
  canvas.setPointerCapture(event.pointerId);
  parts.bodies.get(body)?.classList.add("grabbed");
  $("grab-point").setAttribute("visibility", "visible");
  enqueue({ type: "grab", body, at }, performance.now());
  draw();
}

// Drag targets are sent from `pointerrawupdate` where the browser has it:
// `pointermove` is held back until the start of the next animation frame,
// so its answer could only be painted one frame later; the raw event comes
// as soon as the pointer moves, and its answer usually makes the next paint.
const RAW = "onpointerrawupdate" in window;
function dragTo(event) {
  if (!grabbed) return;
  const t0 = Math.min(event.timeStamp, performance.now());
  const to = toWorld(event);
  grabbed.world = to;
  enqueue({ type: "drag", to }, t0);
}
canvas.addEventListener(RAW ? "pointerrawupdate" : "pointermove", dragTo);

// The server refused a grab (a geared mechanism with no plan to drag it
// through, say): the drags and the release queued for it are dropped, so
// its message stays in the status rather than being replaced by "nothing
// is grabbed" or by the release's frame; the body is let go at once unless
// it was grabbed again since.
function refusedGrab() {
  const next = outbox.findIndex((item) => item.message.type === "grab");
  const stale = outbox.slice(0, next < 0 ? outbox.length : next).filter((item) => ["drag", "release"].includes(item.message.type));
  for (const item of stale) outbox.splice(outbox.indexOf(item), 1);
  if (next >= 0 || !grabbed) return;
  parts.bodies.get(grabbed.body)?.classList.remove("grabbed");
  grabbed = null;
  $("grab-point").setAttribute("visibility", "hidden");
}

function release() {
  if (!grabbed) return;
  parts.bodies.get(grabbed.body)?.classList.remove("grabbed");
  grabbed = null;
  $("grab-point").setAttribute("visibility", "hidden");
  enqueue({ type: "release" }, performance.now());
}
canvas.addEventListener("pointerup", release);
canvas.addEventListener("pointercancel", release);

// ---- the sweep ------------------------------------------------------------------

let playing = false;
let playIndex = 0;

function stopPlaying() {
  playing = false;
  const b = $("play");
  b.dataset.playing = "false";
  b.textContent = "Play sweep";
}

$("play").addEventListener("click", () => {
  if (playing) return stopPlaying();
  playing = true;
  const b = $("play");
  b.dataset.playing = "true";
  b.textContent = "Pause";
  playStep();
});

// The next frame of the file's sweep (each input it moves takes the value
// `dofplan simulate` gives that frame), wrapping around at the end.
function playStep() {
  if (!playing || !doc.sweep) return;
  const { steps, inputs } = doc.sweep;
  const i = playIndex % steps;
  for (const w of inputs) {
    values[w.input] = steps <= 1 || i === 0 ? w.from : i === steps - 1 ? w.to : w.from + ((w.to - w.from) * i) / (steps - 1);
  }
  playIndex = i + 1;
  canvasInputs().forEach((slider, k) => {
    slider.value = values[k];
  });
  sendInputs();
}

// ---- construct (MechEdit §5.1: constraints added in a solved state) ----------
//
// Every edit is sent to the server, which makes it on the file at the pose
// on screen (the pose becomes the drawing first) and answers with the new
// document, or with the message `dofplan check` would print and no change.

// Pixels within which a click or a drop is on a marker or a joint.
const SNAP = 8;
let mode = "move";
let selection = null; // {kind: "joint" | "marker" | "body", name}
let sketch = []; // the body being drawn: [{at, key}] (key: the marker snapped to)
let hover = null; // the pointer, in world coordinates, while drawing
let moving = null; // a marker dragged in edit mode: {key, body, from, at, moved, target, joint}
let panning = null; // {x, y, ox, oy} while panning
let orbiting = null; // {x, y, yaw, pitch} while turning a spatial view
let spaceHeld = false;
let openDiscard = null; // the file whose unsaved changes the next Open drops

function sendEdits(edits) {
  enqueue({ type: "edit", edits }, performance.now());
}

const HINTS = {
  move: "Drag any moving body with the mouse; the sliders drive the inputs.",
  edit: "Click a joint, marker or body to select it. Drag a marker to move it; drop it on another body's marker to join them.",
  body: "Click two or more points (on a marker to join there); Enter or double-click finishes, Escape cancels.",
  marker: "Click on a body to add a marker to it, or off every body to add one to the ground.",
};

function setMode(next) {
  mode = next;
  sketch = [];
  moving = null;
  for (const b of document.querySelectorAll("#modes button")) b.classList.toggle("active", b.dataset.mode === mode);
  canvas.dataset.mode = mode;
  $("hint").textContent = HINTS[mode];
  draw();
}

for (const b of document.querySelectorAll("#modes button")) b.addEventListener("click", () => setMode(b.dataset.mode));

// The screen position of the pointer in the canvas.
function screenOf(event) {
  const rect = canvas.getBoundingClientRect();
  return [event.clientX - rect.left, event.clientY - rect.top];
}

// The marker nearest the screen point `p` within SNAP pixels (the last drawn
// wins among coincident ones: it is on top), not of body `except`.
function markerNear(p, except = null) {
  if (!pose) return null;
  let best = null;
  pose.markers.forEach(([x, y], i) => {
    if (except !== null && markerIndex[i].body === except) return;
    const d = Math.hypot(sx(x) - p[0], sy(y) - p[1]);
    if (d <= SNAP && (!best || d <= best.d)) best = { i, key: markerIndex[i].key, d };
  });
  return best;
}

// The joint whose pin is within SNAP pixels of `p`.
function jointNear(p) {
  if (!pose) return null;
  const index = new Map(markerIndex.map((m, i) => [m.key, i]));
  let best = null;
  for (const j of doc.joints) {
    const [x, y] = pose.markers[index.get(j.markers[1])];
    const d = Math.hypot(sx(x) - p[0], sy(y) - p[1]);
    if (d <= SNAP && (!best || d < best.d)) best = { name: j.name, d };
  }
  return best;
}

function bodyUnder(event) {
  const g = event.target.closest && event.target.closest("[data-body]");
  return g ? g.dataset.body : null;
}

function select(next) {
  selection = next;
  markSelection();
}

// Marks the selection in the drawing and the toolbar; a selection the
// document no longer has is dropped.
function markSelection() {
  for (const e of canvas.querySelectorAll(".selected")) e.classList.remove("selected");
  let element = null;
  if (selection && doc) {
    const attribute = { joint: "data-joint", marker: "data-marker", body: "data-body" }[selection.kind];
    element = canvas.querySelector(`[${attribute}="${CSS.escape(selection.name)}"]`);
    if (!element) selection = null;
  }
  if (element) element.classList.add("selected");
  const joint = selection && selection.kind === "joint" ? doc.joints.find((j) => j.name === selection.name) : null;
  const driven = joint && doc.inputs.some((i) => i.joint === joint.name);
  $("selection").textContent = selection
    ? `${selection.kind} ${selection.name}${joint ? ` (${joint.kind}${driven ? ", an input" : ""})` : ""}`
    : "nothing selected";
  const editable = Boolean(doc && doc.editing.editable);
  $("toggle").disabled = !editable || !joint;
  // A prismatic joint's line (its first marker's direction, turned with
  // its body), editable.
  const sliding = editable && joint && joint.kind === "prismatic" && pose;
  $("direction-box").hidden = !sliding;
  if (sliding && document.activeElement !== $("direction")) {
    const [dx, dy] = lineOf(joint);
    $("direction").value = ((Math.atan2(dy, dx) * 180) / Math.PI).toFixed(1);
  }
  $("make-input").disabled = !editable || !joint || driven;
  $("delete").disabled = !editable || !selection;
  showNumeric(editable);
  const marker = selection && selection.kind === "marker" ? selection.name : null;
  const traced = Boolean(marker && doc.sweep && (doc.sweep.trace || []).includes(marker));
  $("trace").disabled = !editable || !marker || !doc.sweep;
  $("trace").setAttribute("aria-pressed", String(traced));
  $("trace").title = doc && doc.sweep ? "Trace the selected marker over the sweep, or stop tracing it (T)" : "Set a sweep first (the Sweep box beside the drawing)";
  drawLengths();
}

// Numeric entry: the selected marker's coordinates, or a length of the
// selected link, as the pose on screen has them (a field being typed in
// is left alone).
function showNumeric(editable) {
  const marker = editable && pose && selection && selection.kind === "marker" ? markerIndex.findIndex((m) => m.key === selection.name) : -1;
  $("marker-box").hidden = marker < 0;
  if (marker >= 0) {
    const [x, y] = pose.markers[marker];
    if (document.activeElement !== $("marker-x")) $("marker-x").value = fmt(x);
    if (document.activeElement !== $("marker-y")) $("marker-y").value = fmt(y);
  }
  const body = editable && pose && selection && selection.kind === "body" ? doc.bodies.find((b) => b.name === selection.name) : null;
  $("length-box").hidden = !body || body.markers.length < 2;
  if (!body || body.markers.length < 2) return;
  const list = $("length-pair");
  const chosen = list.value;
  const options = [];
  for (let a = 0; a < body.markers.length; a++) {
    for (let b = a + 1; b < body.markers.length && options.length < 28; b++) {
      options.push(`${body.markers[a].name}–${body.markers[b].name}`);
    }
  }
  if (list.dataset.link !== body.name || list.options.length !== options.length) {
    list.replaceChildren(
      ...options.map((o) => {
        const option = document.createElement("option");
        option.value = option.textContent = o;
        return option;
      }),
    );
    list.dataset.link = body.name;
  }
  if (options.includes(chosen)) list.value = chosen;
  if (document.activeElement !== $("length")) $("length").value = fmt(pairLength().length);
}

// The selected link's chosen pair: their keys, positions and distance.
function pairLength() {
  const [a, b] = $("length-pair").value.split("–").map((m) => `${selection.name}.${m}`);
  const [pa, pb] = [a, b].map((key) => pose.markers[markerIndex.findIndex((m) => m.key === key)]);
  return { a, b, pa, pb, length: Math.hypot(pb[0] - pa[0], pb[1] - pa[1]) };
}

function moveSelectedMarker() {
  if (!selection || selection.kind !== "marker") return;
  const [x, y] = [Number($("marker-x").value), Number($("marker-y").value)];
  if ($("marker-x").value.trim() === "" || $("marker-y").value.trim() === "" || !Number.isFinite(x) || !Number.isFinite(y)) {
    showStatus("error", "a marker's coordinates are two numbers");
    return;
  }
  sendEdits([{ op: "move_marker", marker: selection.name, to: [x, y] }]);
}
for (const id of ["marker-x", "marker-y"]) {
  $(id).addEventListener("keydown", (e) => {
    if (e.key === "Enter") moveSelectedMarker();
  });
}

// A typed length moves the pair's second marker along the line from the
// first (with what is pinned to it, as a drag of it would).
function setLength() {
  if (!selection || selection.kind !== "body") return;
  const want = Number($("length").value);
  if ($("length").value.trim() === "" || !Number.isFinite(want) || want <= 0) {
    showStatus("error", "a length is a number above 0");
    return;
  }
  const { b, pa, pb, length } = pairLength();
  const [ux, uy] = length > 1e-12 ? [(pb[0] - pa[0]) / length, (pb[1] - pa[1]) / length] : [1, 0];
  sendEdits([{ op: "move_marker", marker: b, to: [pa[0] + want * ux, pa[1] + want * uy] }]);
}
$("length").addEventListener("keydown", (e) => {
  if (e.key === "Enter") setLength();
});
$("length-pair").addEventListener("change", () => {
  $("length").value = fmt(pairLength().length);
  drawLengths();
});

function toggleTrace() {
  if (!selection || selection.kind !== "marker" || !doc.editing.editable) return;
  if (!doc.sweep) {
    showStatus("error", "the file has no sweep to trace a marker over: set one in the Sweep box first");
    return;
  }
  const on = !(doc.sweep.trace || []).includes(selection.name);
  sendEdits([{ op: "trace", marker: selection.name, on }]);
}
$("trace").addEventListener("click", toggleTrace);

// ---- the sweep editor -------------------------------------------------------

function showSweep() {
  const s = doc.sweep;
  const editable = Boolean(doc.editing && doc.editing.editable);
  const first = s && s.inputs[0];
  const name = (k) => (doc.inputs[k] ? doc.inputs[k].name : `#${k}`);
  $("sweep-summary").textContent = s
    ? `Sweep: ${s.inputs.map((w) => `${name(w.input)} ${fmt(w.from)} → ${fmt(w.to)}`).join(", ")}, ${s.steps} steps`
    : doc.inputs.length
      ? "Sweep: none (set one to play the motion and trace markers)"
      : "Sweep: none (mark a joint as an input first)";
  const list = $("sweep-input");
  const chosen = list.value;
  list.replaceChildren(
    ...doc.inputs.map((input) => {
      const o = document.createElement("option");
      o.value = o.textContent = input.name;
      return o;
    }),
  );
  if (first) list.value = name(first.input);
  else if (doc.inputs.some((i) => i.name === chosen)) list.value = chosen;
  const input = doc.inputs.find((i) => i.name === list.value);
  const typing = (id) => document.activeElement === $(id);
  if (!typing("sweep-from")) $("sweep-from").value = first ? fmt(first.from) : input && input.kind === "slide" ? fmt(-doc.size) : "0";
  if (!typing("sweep-to")) $("sweep-to").value = first ? fmt(first.to) : input && input.kind === "slide" ? fmt(doc.size) : "360";
  if (!typing("sweep-steps")) $("sweep-steps").value = s ? String(s.steps) : input && input.kind === "slide" ? "101" : "361";
  for (const id of ["sweep-input", "sweep-from", "sweep-to", "sweep-steps", "sweep-set"]) $(id).disabled = !editable || !doc.inputs.length;
  $("sweep-delete").disabled = !editable || !s;
  const traced = $("traced");
  traced.replaceChildren();
  if (s) {
    const label = document.createElement("span");
    label.textContent = (s.trace || []).length ? "traced:" : "no marker traced (select one, then Trace or T)";
    traced.appendChild(label);
    for (const key of s.trace || []) {
      const chip = document.createElement("span");
      chip.className = "chip";
      chip.dataset.traced = key;
      chip.textContent = key;
      const remove = document.createElement("button");
      remove.type = "button";
      remove.textContent = "×";
      remove.title = `stop tracing ${key}`;
      remove.disabled = !editable;
      remove.addEventListener("click", () => sendEdits([{ op: "trace", marker: key, on: false }]));
      chip.appendChild(remove);
      traced.appendChild(chip);
    }
  }
}

function setSweep() {
  const [from, to, steps] = ["sweep-from", "sweep-to", "sweep-steps"].map((id) => Number($(id).value));
  if (![from, to, steps].every(Number.isFinite) || !Number.isInteger(steps) || steps < 0) {
    showStatus("error", "a sweep is two numbers (from, to) and a whole number of steps");
    return;
  }
  sendEdits([{ op: "set_sweep", input: $("sweep-input").value, from, to, steps }]);
}
$("sweep-set").addEventListener("click", setSweep);
for (const id of ["sweep-from", "sweep-to", "sweep-steps"]) {
  $(id).addEventListener("keydown", (e) => {
    if (e.key === "Enter") setSweep();
  });
}
$("sweep-delete").addEventListener("click", () => sendEdits([{ op: "delete_sweep" }]));

// ---- the File tab: the file's text, and a file that does not load -----------

let textTyped = false; // the text area holds typing not applied yet

function showFile() {
  const area = $("file-text");
  const text = doc.editing ? doc.editing.text : null;
  area.disabled = text === null || text === undefined;
  $("file-apply").disabled = area.disabled;
  $("file-revert").disabled = area.disabled;
  if (area.disabled) {
    area.value = "";
    $("file-note").textContent = doc.editing && doc.editing.why ? `shown, not edited: ${doc.editing.why}` : "";
  } else if (!textTyped || documentFor === "text" || documentFor === "open") {
    area.value = text;
    textTyped = false;
    $("file-note").textContent = "";
  } else {
    $("file-note").textContent = "the document changed since you typed here: Revert shows it";
  }
  if (doc.broken) showFileErrors(doc.broken.message, doc.broken.errors);
  else showFileErrors(null, []);
}

// The errors above the text, each place a button that selects it in the
// text; the gutter marks their lines.
let errorLines = new Set();
function showFileErrors(message, errors) {
  const box = $("file-errors");
  box.hidden = !message;
  box.replaceChildren();
  errorLines = new Set();
  if (message) {
    for (const e of errors) {
      const go = document.createElement("button");
      go.type = "button";
      go.className = "goto";
      go.dataset.line = e.line;
      go.textContent = `line ${e.line}, column ${e.column}`;
      go.title = e.message;
      go.addEventListener("click", () => selectInText(e));
      box.appendChild(go);
      for (let l = e.line; l <= Math.max(e.line, e.end_line); l++) errorLines.add(l);
    }
    const pre = document.createElement("div");
    pre.textContent = message;
    box.appendChild(pre);
  }
  renderGutter();
}

// The places a refusal's message points at (`file:line:column`).
function placesIn(message) {
  const places = [];
  for (const m of message.matchAll(/:(\d+):(\d+)/g)) {
    const [line, column] = [Number(m[1]), Number(m[2])];
    if (!places.some((p) => p.line === line && p.column === column)) places.push({ line, column, end_line: line, end_column: column + 1, message: "" });
  }
  return places;
}

function renderGutter() {
  const lines = $("file-text").value.split("\n").length;
  const gutter = $("file-gutter");
  gutter.replaceChildren();
  for (let l = 1; l <= lines; l++) {
    const span = document.createElement("span");
    span.textContent = String(l);
    if (errorLines.has(l)) span.className = "error-line";
    gutter.append(span, "\n");
  }
  gutter.scrollTop = $("file-text").scrollTop;
}

// Selects an error's place in the text and scrolls to it.
function selectInText(e) {
  const area = $("file-text");
  const lines = area.value.split("\n");
  const offset = (line, column) => lines.slice(0, line - 1).reduce((n, l) => n + l.length + 1, 0) + column - 1;
  const start = offset(e.line, e.column);
  const end = Math.max(start + 1, offset(e.end_line, e.end_column));
  area.focus();
  area.setSelectionRange(start, Math.min(end, area.value.length));
  area.scrollTop = Math.max(0, (e.line - 3) * 16);
  $("file-gutter").scrollTop = area.scrollTop;
}

function applyText() {
  if ($("file-text").disabled) return;
  enqueue({ type: "text", text: $("file-text").value }, performance.now());
}
$("file-apply").addEventListener("click", applyText);
$("file-revert").addEventListener("click", () => {
  textTyped = false;
  documentFor = "text";
  showFile();
});
$("file-text").addEventListener("input", () => {
  textTyped = true;
  renderGutter();
});
$("file-text").addEventListener("scroll", () => {
  $("file-gutter").scrollTop = $("file-text").scrollTop;
});
$("file-text").addEventListener("keydown", (e) => {
  if (e.key === "Enter" && (e.ctrlKey || e.metaKey)) {
    e.preventDefault();
    applyText();
  }
});

// The editing controls as the document allows them.
function showEditing() {
  const e = doc.editing;
  for (const b of document.querySelectorAll("#modes button")) b.disabled = !e.editable && b.dataset.mode !== "move";
  if (!e.editable && mode !== "move") setMode("move");
  $("modes").title = e.editable ? "" : `not editable: ${e.why}`;
  if (is3d()) {
    $("hint").textContent = "Drag to orbit, wheel to zoom, middle or Space+drag to pan; the sliders drive the inputs. Spatial files are shown, not edited.";
  }
  $("undo").disabled = !e.undo;
  $("redo").disabled = !e.redo;
  $("save").disabled = !e.editable;
  $("save-as").disabled = !e.editable;
  $("file").dataset.dirty = String(e.dirty);
  $("file").textContent = `${doc.file}${e.dirty ? " (unsaved)" : ""}`;
  const list = $("open-file");
  const chosen = list.value;
  list.replaceChildren(
    ...e.files.map((f) => {
      const o = document.createElement("option");
      o.value = o.textContent = f;
      return o;
    }),
  );
  if (e.files.length === 0) {
    const o = document.createElement("option");
    o.textContent = "no .toml files here";
    list.appendChild(o);
  }
  list.disabled = e.files.length === 0;
  // The choice made stays; else the file open now is shown chosen.
  if (e.files.includes(chosen) && chosen !== shownFile) list.value = chosen;
  else if (e.files.includes(doc.file)) list.value = doc.file;
  shownFile = doc.file;
  // A spatial page is a view of its file alone: another file is opened
  // by starting the editor with it.
  $("open").disabled = e.files.length === 0 || is3d();
  // The grid is the drawing plane's: a spatial view has its floor instead.
  $("grid-toggle").disabled = is3d();
  if (is3d() && gridOn) setGrid(false);
  list.disabled ||= is3d();
  markSelection();
}

// A new body's name and its markers' (as the server names them: the
// first free `linkN`; markers A, B, … then M1, …).
function newBodyName() {
  const taken = new Set(doc.bodies.map((b) => b.name));
  for (let n = 1; ; n++) if (!taken.has(`link${n}`)) return `link${n}`;
}
const markerName = (k) => (k < 26 ? String.fromCharCode(65 + k) : `M${k - 25}`);

function finishBody() {
  if (sketch.length === 0) return;
  const name = newBodyName();
  const edits = [{ op: "add_body", name, markers: sketch.map((p) => p.at) }];
  sketch.forEach((p, k) => {
    // A point put on a marker is joined to it there.
    if (p.key) edits.push({ op: "join", a: p.key, b: `${name}.${markerName(k)}`, snap: true });
  });
  sketch = [];
  sendEdits(edits);
  draw();
}

function deleteSelection() {
  if (!selection) return;
  const op = { joint: "delete_joint", marker: "delete_marker", body: "delete_body" }[selection.kind];
  const key = { joint: "joint", marker: "marker", body: "body" }[selection.kind];
  sendEdits([{ op, [key]: selection.name }]);
}

// The world direction of prismatic `joint`'s line in the pose on screen.
function lineOf(joint) {
  const a = markerIndex.findIndex((m) => m.key === joint.markers[0]);
  const dir = markerAt(a).dir || [1, 0];
  const [c, s] = pose.poses[markerIndex[a].body];
  return [c * dir[0] - s * dir[1], s * dir[0] + c * dir[1]];
}

$("direction").addEventListener("change", () => {
  const joint = selection && selection.kind === "joint" ? doc.joints.find((j) => j.name === selection.name) : null;
  const degrees = Number($("direction").value);
  if (!joint || joint.kind !== "prismatic" || !Number.isFinite(degrees)) return;
  const r = (degrees * Math.PI) / 180;
  // Sent as the line in the pose on screen, which the edit makes the
  // drawing first.
  sendEdits([{ op: "set_dir", marker: joint.markers[0], dir: [Math.cos(r), Math.sin(r)] }]);
});

function toggleJoint(want = null) {
  if (!selection || selection.kind !== "joint") return;
  const joint = doc.joints.find((j) => j.name === selection.name);
  if (!joint || (want && joint.kind === want)) return;
  sendEdits([{ op: "toggle", joint: joint.name }]);
}

function makeInput() {
  if (selection && selection.kind === "joint") sendEdits([{ op: "add_input", joint: selection.name }]);
}

$("toggle").addEventListener("click", () => toggleJoint());
$("make-input").addEventListener("click", makeInput);
$("delete").addEventListener("click", deleteSelection);
$("undo").addEventListener("click", () => enqueue({ type: "undo" }, performance.now()));
$("redo").addEventListener("click", () => enqueue({ type: "redo" }, performance.now()));
$("fit").addEventListener("click", () => fitView());

function save() {
  if (!doc) return;
  if (!doc.editing.named) {
    showStatus("error", "this document has no file yet: type a name beside Save as");
    $("save-name").focus();
    return;
  }
  enqueue({ type: "save" }, performance.now());
}
$("save").addEventListener("click", save);
$("save-as").addEventListener("click", () => enqueue({ type: "save", name: $("save-name").value }, performance.now()));
$("save-name").addEventListener("keydown", (e) => {
  if (e.key === "Enter") $("save-as").click();
});
$("open").addEventListener("click", () => {
  const name = $("open-file").value;
  enqueue({ type: "open", name, discard: openDiscard === name }, performance.now());
  openDiscard = null;
});

// Pointer on the canvas: pan (middle button, or Space held), and the edit
// modes. Move mode's grab is the bodies' own listener.
canvas.addEventListener("pointerdown", (event) => {
  if (!doc || !pose) return;
  if (event.button === 1 || (event.button === 0 && spaceHeld)) {
    event.preventDefault();
    panning = { x: event.clientX, y: event.clientY, ox: view.ox, oy: view.oy };
    canvas.setPointerCapture(event.pointerId);
    return;
  }
  if (event.button === 0 && is3d()) {
    // A spatial document turns under the pointer (it is not dragged).
    event.preventDefault();
    orbiting = { x: event.clientX, y: event.clientY, yaw: camera.yaw, pitch: camera.pitch };
    canvas.setPointerCapture(event.pointerId);
    return;
  }
  if (event.button !== 0 || mode === "move") return;
  const p = screenOf(event);
  const at = toWorld(event);
  if (mode === "body") {
    const near = markerNear(p);
    sketch.push(near ? { at: pose.markers[near.i].slice(), key: near.key } : { at: snapped(at), key: null });
    draw();
  } else if (mode === "marker") {
    const body = bodyUnder(event) ?? doc.bodies.find((b) => b.fixed).name;
    sendEdits([{ op: "add_marker", body, at: snapped(at) }]);
  } else if (mode === "edit") {
    const near = markerNear(p);
    const joint = jointNear(p);
    if (near) {
      canvas.setPointerCapture(event.pointerId);
      moving = { key: near.key, body: markerIndex[near.i].body, from: p, at, moved: false, target: null, joint, shift: event.shiftKey };
    } else {
      const body = bodyUnder(event);
      select(body && !doc.bodies.find((b) => b.name === body).fixed ? { kind: "body", name: body } : null);
    }
  }
});

// A double-click finishes the body being drawn; its two clicks put one
// point (pointer events carry no click count to tell them apart sooner).
canvas.addEventListener("dblclick", () => {
  if (mode !== "body" || sketch.length === 0) return;
  const [a, b] = sketch.slice(-2).map((p) => [sx(p.at[0]), sy(p.at[1])]);
  if (b && Math.hypot(a[0] - b[0], a[1] - b[1]) <= SNAP) sketch.pop();
  finishBody();
});

canvas.addEventListener("pointermove", (event) => {
  if (orbiting) {
    camera.yaw = orbiting.yaw + (event.clientX - orbiting.x) * 0.01;
    const pitch = orbiting.pitch + (event.clientY - orbiting.y) * 0.01;
    camera.pitch = Math.max(-Math.PI / 2, Math.min(Math.PI / 2, pitch));
    renderTraces();
    return;
  }
  if (panning) {
    view.ox = panning.ox + event.clientX - panning.x;
    view.oy = panning.oy + event.clientY - panning.y;
    userView = true;
    renderTraces();
    return;
  }
  if (mode === "body") {
    const near = pose && markerNear(screenOf(event));
    hover = near ? pose.markers[near.i].slice() : snapped(toWorld(event));
    drawPreview();
  } else if (moving) {
    const p = screenOf(event);
    moving.moved ||= Math.hypot(p[0] - moving.from[0], p[1] - moving.from[1]) > 3;
    const target = markerNear(p, moving.body);
    moving.target = target ? target.key : null;
    moving.at = target ? pose.markers[target.i].slice() : snapped(toWorld(event));
    drawPreview();
  }
  showPointer(event);
});
canvas.addEventListener("pointerleave", () => {
  $("pointer").textContent = "";
});

// The pointer's world coordinates (where a click would put a point: on the
// grid when it is on), and while drawing or dragging a marker, the length
// being drawn.
function showPointer(event) {
  if (!doc || is3d()) {
    $("pointer").textContent = "";
    return;
  }
  let at = snapped(toWorld(event));
  if (mode === "body" && hover) at = hover;
  if (moving && moving.moved) at = moving.at;
  let text = `x ${fmt(at[0])}  y ${fmt(at[1])}`;
  if (mode === "body" && sketch.length) {
    const last = sketch[sketch.length - 1].at;
    text += `  length ${fmt(Math.hypot(at[0] - last[0], at[1] - last[1]))}`;
  }
  $("pointer").textContent = text;
}

// A length or coordinate as the page shows it: at most 4 decimals.
function fmt(v) {
  const r = Number(v.toFixed(4));
  return Object.is(r, -0) ? "0" : String(r);
}

function endPointer() {
  orbiting = null;
  if (panning) {
    panning = null;
    return;
  }
  if (!moving) return;
  const m = moving;
  moving = null;
  if (!m.moved) {
    // A click: the joint there, or (Shift, or no joint) the marker.
    select(m.joint && !m.shift ? { kind: "joint", name: m.joint.name } : { kind: "marker", name: m.key });
  } else if (m.target) {
    // Dropped on another body's marker: snapped onto it and joined.
    sendEdits([{ op: "join", a: m.target, b: m.key, snap: true }]);
  } else {
    sendEdits([{ op: "move_marker", marker: m.key, to: m.at }]);
  }
  draw();
}
canvas.addEventListener("pointerup", endPointer);
canvas.addEventListener("pointercancel", endPointer);

// The wheel zooms about the pointer.
canvas.addEventListener(
  "wheel",
  (event) => {
    event.preventDefault();
    const [px, py] = screenOf(event);
    const [wx, wy] = toWorld(event);
    const s = Math.min(1e6, Math.max(1e-3, view.s * Math.exp(-event.deltaY * 0.0015)));
    view = { s, ox: px - s * wx, oy: py + s * wy };
    userView = true;
    renderTraces();
  },
  { passive: false },
);

// The body being drawn, or the marker being dragged, over the drawing.
function drawPreview() {
  const g = $("preview");
  if (!g) return;
  g.replaceChildren();
  if (mode === "body" && sketch.length) {
    const points = sketch.map((p) => p.at);
    if (hover) points.push(hover);
    el("polyline", { class: "sketch", points: points.map(([x, y]) => `${sx(x).toFixed(1)},${sy(y).toFixed(1)}`).join(" ") }, g);
    for (const p of sketch) el("circle", { class: p.key ? "sketch-point snapped" : "sketch-point", r: 4, cx: sx(p.at[0]), cy: sy(p.at[1]) }, g);
  }
  if (moving && moving.moved) {
    const i = markerIndex.findIndex((m) => m.key === moving.key);
    const [x0, y0] = pose.markers[i];
    const [x1, y1] = moving.at;
    el("line", { class: "move-line", x1: sx(x0), y1: sy(y0), x2: sx(x1), y2: sy(y1) }, g);
    el("circle", { class: moving.target ? "move-ghost snapped" : "move-ghost", r: moving.target ? 7 : 4.5, cx: sx(x1), cy: sy(y1) }, g);
  }
  drawLengths();
}

// Lengths written along what is being drawn or dragged, and along the
// selected link's sides: the body being drawn (each segment, to the
// pointer too), a dragged marker's distances to its body's other markers,
// a selected link's (its outline's sides).
function drawLengths() {
  const g = $("lengths");
  g.replaceChildren();
  if (!doc || !pose || is3d()) return;
  const pairs = [];
  if (mode === "body" && sketch.length) {
    const points = sketch.map((p) => p.at);
    if (hover) points.push(hover);
    for (let k = 1; k < points.length; k++) pairs.push([points[k - 1], points[k]]);
  } else if (moving && moving.moved) {
    const i = markerIndex.findIndex((m) => m.key === moving.key);
    markerIndex.forEach((m, j) => {
      if (j !== i && m.body === moving.body && !doc.bodies[m.body].fixed) pairs.push([pose.markers[j], moving.at]);
    });
  } else if (selection && selection.kind === "body") {
    const bi = doc.bodies.findIndex((b) => b.name === selection.name);
    const outline = hulls[bi] || [];
    const sides = outline.length === 2 ? [[outline[0], outline[1]]] : outline.map((a, k) => [a, outline[(k + 1) % outline.length]]);
    for (const [a, b] of sides) pairs.push([pose.markers[a], pose.markers[b]]);
  }
  for (const [a, b] of pairs) {
    const length = Math.hypot(b[0] - a[0], b[1] - a[1]);
    if (length < 1e-12) continue;
    // Beside the side's middle, on its left as drawn.
    const [mx, my] = [sx((a[0] + b[0]) / 2), sy((a[1] + b[1]) / 2)];
    const [nx, ny] = [-(b[1] - a[1]) / length, -(b[0] - a[0]) / length];
    const label = el("text", { class: "length-label", x: (mx + 12 * nx - 14).toFixed(1), y: (my + 12 * ny + 4).toFixed(1) }, g);
    label.textContent = fmt(length);
  }
}

// The world axes as the 3D view turns them, in the drawing's lower left
// corner; nothing for a planar document.
function drawAxes() {
  const g = $("axes");
  if (!is3d()) {
    if (g.childElementCount) g.replaceChildren();
    return;
  }
  if (!g.childElementCount) {
    for (const name of ["x", "y", "z"]) {
      el("line", { class: `axis axis-${name}` }, g);
      el("text", { class: `axis-label axis-${name}` }, g).textContent = name;
    }
  }
  const rect = canvas.getBoundingClientRect();
  const [x0, y0] = [40, rect.height - 60];
  [[1, 0, 0], [0, 1, 0], [0, 0, 1]].forEach((unit, k) => {
    const [u, v] = project(unit);
    const [x1, y1] = [x0 + 28 * u, y0 - 28 * v];
    const line = g.children[2 * k];
    for (const [a, value] of Object.entries({ x1: x0, y1: y0, x2: x1, y2: y1 })) line.setAttribute(a, value.toFixed(1));
    const label = g.children[2 * k + 1];
    label.setAttribute("x", (x0 + 36 * u - 3).toFixed(1));
    label.setAttribute("y", (y0 - 36 * v + 4).toFixed(1));
  });
}

function typing(event) {
  return event.target.matches && event.target.matches("input:not([type=range]), select, textarea");
}

document.addEventListener("keydown", (event) => {
  if (event.key === " " && !typing(event)) {
    // Held to pan: neither a scroll nor a press of the focused button.
    spaceHeld = true;
    event.preventDefault();
  }
  if (typing(event)) return;
  const ctrl = event.ctrlKey || event.metaKey;
  const key = event.key.toLowerCase();
  if (ctrl && key === "z") {
    event.preventDefault();
    enqueue({ type: event.shiftKey ? "redo" : "undo" }, performance.now());
  } else if (ctrl && key === "y") {
    event.preventDefault();
    enqueue({ type: "redo" }, performance.now());
  } else if (ctrl && key === "s") {
    event.preventDefault();
    save();
  } else if (ctrl || event.altKey) {
    return;
  } else if (event.key === "Enter" && mode === "body") {
    // Not also a press of the focused button (the mode's, say).
    event.preventDefault();
    finishBody();
  } else if (event.key === "Escape") {
    if (sketch.length || moving) {
      sketch = [];
      moving = null;
      draw();
    } else select(null);
  } else if (event.key === "Delete" || event.key === "Backspace") {
    event.preventDefault();
    if (mode === "body" && sketch.length) {
      sketch.pop();
      draw();
    } else deleteSelection();
  } else if (key === "r") toggleJoint("revolute");
  else if (key === "p") toggleJoint("prismatic");
  else if (key === "i") makeInput();
  else if (key === "f") fitView();
  else if (key === "g") setGrid(!gridOn);
  else if (key === "l" && !$("forces-toggle").hidden) setForces(!forcesOn);
  else if (key === "t") toggleTrace();
  else if (!(doc && doc.editing.editable) && key !== "m") return;
  else if (key === "m") setMode("move");
  else if (key === "e") setMode("edit");
  else if (key === "b") setMode("body");
  else if (key === "n") setMode("marker");
});
document.addEventListener("keyup", (event) => {
  if (event.key === " ") {
    spaceHeld = false;
    if (!typing(event)) event.preventDefault();
  }
});

// ---- panels ------------------------------------------------------------------------

function openTab(name) {
  for (const t of document.querySelectorAll("#tabs button")) t.classList.toggle("active", t.dataset.tab === name);
  for (const p of document.querySelectorAll(".panel")) p.hidden = p.dataset.panel !== name;
  if (name === "file") renderGutter();
}
for (const tab of document.querySelectorAll("#tabs button")) {
  tab.addEventListener("click", () => openTab(tab.dataset.tab));
}

$("policy").addEventListener("change", () => {
  if (doc && doc.inputs.length) sendInputs();
});

// For the test: whether a request is still unanswered, the document, and
// a page point in world coordinates.
probe.busy = () => Boolean(inFlight) || outbox.length > 0;
probe.doc = () => doc;
probe.toWorld = (x, y) => toWorld({ clientX: x, clientY: y });
probe.scale = () => view.s;
probe.pose = () => pose;
probe.selection = () => selection;
probe.toPage = (p) => {
  const rect = canvas.getBoundingClientRect();
  const [x, y] = toScreen(p);
  return [rect.left + x, rect.top + y];
};
probe.camera = () => ({ ...camera });
probe.gridStep = () => (gridOn ? gridStep() : null);
probe.project = (p) => toScreen(p);

new ResizeObserver(() => {
  if (userView) renderTraces();
  else fitView();
  draw();
}).observe(canvas);

connect();
