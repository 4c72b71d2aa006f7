// The stepper's page: every number comes from the JSON API of the `step`
// process that served it (the same interpreter as the terminal front end).
// The view: the frame fitted in the view area, zoomed (wheel around the
// pointer, +/-), panned (drag, Shift+arrows), with a selected pixel that the
// arrow keys move and Enter explains.
"use strict";

const state = {
  frame: null, stages: {}, stage: "final", upto: null,
  pixel: null,      // the explained pixel [x, y]
  pixelUpto: null,  // ... after that many triangles (the slider's point when it was asked), null: the frame's end
  selected: null,   // the selected pixel (the box), which Enter explains
  tile: null, tri: null, hover: null,
};
// Image pixel (x, y) is drawn at view position (ox + x * s, oy + y * s), CSS px.
const view = { s: 1, ox: 0, oy: 0, fit: true };
const $ = (id) => document.getElementById(id);
const GRID_ZOOM = 8;    // device pixels per image pixel from which the pixel grid shows
const MAX_ZOOM = 128;

const SERVER_GONE = "the step server stopped (or cannot be reached): restart `step [SCENE] [flags] --serve` and " +
  "reload this page. What is already shown stays usable (zoom, pan, the texts below).";

class ServerGone extends Error { constructor() { super(SERVER_GONE); } }

async function api(path) {
  let r;
  try {
    r = await fetch(path);
  } catch (e) {
    throw new ServerGone();
  }
  let body;
  try {
    body = await r.json();
  } catch (e) {
    throw new Error(path + ": the server's answer is not JSON (status " + r.status + ")");
  }
  if (!r.ok) throw new Error(body.error || r.statusText);
  return body;
}

function status(text) { $("status").textContent = text || ""; }

// ---------------------------------------------------------------- the image

function imageUrl() {
  if (state.upto !== null) return "/api/upto?n=" + state.upto;
  return "/api/stage?name=" + encodeURIComponent(state.stage);
}

// The displayed image's pixels, for the value under the pointer.
const pixels = { canvas: document.createElement("canvas"), ctx: null, ready: false };

let imageRequest = 0;
let shown = { stage: "final", upto: null };  // what the displayed image is
// Loads the image first and swaps it in when it arrived, so that a failed
// load (a stopped server) keeps the last image on screen, and the controls
// go back to what it shows.
function showImage() {
  const url = imageUrl(), ticket = ++imageRequest, want = { stage: state.stage, upto: state.upto };
  const loader = new Image();
  $("view").classList.add("loading");
  loader.onload = () => {
    if (ticket !== imageRequest) return;
    const img = $("image");
    img.src = url;
    shown = want;
    const c = pixels.canvas;
    c.width = loader.naturalWidth;
    c.height = loader.naturalHeight;
    pixels.ctx = c.getContext("2d", { willReadFrequently: true });
    pixels.ctx.drawImage(loader, 0, 0);
    pixels.ready = true;
    $("view").classList.remove("loading");
    status("");
    placeImage();
    showValue();
  };
  loader.onerror = async () => {
    if (ticket !== imageRequest) return;
    $("view").classList.remove("loading");
    if ($("image").src) {
      state.stage = shown.stage;
      state.upto = shown.upto;
      showControls();
    }
    try {
      await api("/api/frame");
      status("the image " + url + " could not be drawn");
    } catch (e) { showError(e); }
  };
  loader.src = url;
}

function showError(e) { status(e.message); }

// The stage list, the slider, the sentence and the legend for state.stage and state.upto.
function showControls() {
  $("stage").value = state.stage;
  const up = $("upto");
  up.value = state.upto === null ? up.max : state.upto;
  $("upto-value").textContent = state.upto === null ? "all" : String(state.upto);
  $("stage-about").textContent = state.upto !== null
    ? "The frame after the first " + state.upto + " triangles in submission order, drawn by the real pipeline."
    : state.stages[state.stage].about;
  showLegend();
  updatePixelNote();
}

// ---------------------------------------------------------------- view transform

// The view's inner size in CSS px, fractions kept (clientWidth rounds).
function viewSize() {
  const v = $("view"), r = v.getBoundingClientRect(), cs = getComputedStyle(v);
  const bx = parseFloat(cs.borderLeftWidth) + parseFloat(cs.borderRightWidth);
  const by = parseFloat(cs.borderTopWidth) + parseFloat(cs.borderBottomWidth);
  return [r.width - bx, r.height - by];
}

function fitScale() {
  const [w, h] = viewSize(), f = state.frame;
  return Math.min(w / f.width, h / f.height);
}

function minScale() { return Math.min(fitScale(), 1) / 4; }

function fitView() {
  const [w, h] = viewSize(), f = state.frame;
  view.s = fitScale();
  view.ox = (w - f.width * view.s) / 2;
  view.oy = (h - f.height * view.s) / 2;
  view.fit = true;
  placeImage();
}

// Keeps some of the image in the view.
function clampPan() {
  const [w, h] = viewSize(), f = state.frame, keep = 32;
  view.ox = Math.min(w - keep, Math.max(keep - f.width * view.s, view.ox));
  view.oy = Math.min(h - keep, Math.max(keep - f.height * view.s, view.oy));
}

// Zooms by `factor` keeping view point (cx, cy) on the same image point.
function zoomAt(cx, cy, factor) {
  const s = Math.min(MAX_ZOOM, Math.max(minScale(), view.s * factor));
  view.ox = cx - (cx - view.ox) * s / view.s;
  view.oy = cy - (cy - view.oy) * s / view.s;
  view.s = s;
  view.fit = false;
  clampPan();
  placeImage();
}

// The zoom centre for keys and buttons: the selected pixel when it is in
// the view, else the view's centre.
function zoomCentre() {
  const [w, h] = viewSize();
  if (state.selected) {
    const x = view.ox + (state.selected[0] + 0.5) * view.s, y = view.oy + (state.selected[1] + 0.5) * view.s;
    if (x >= 0 && y >= 0 && x < w && y < h) return [x, y];
  }
  return [w / 2, h / 2];
}

function zoomBy(factor) {
  const [cx, cy] = zoomCentre();
  zoomAt(cx, cy, factor);
}

function oneToOne() {
  const [cx, cy] = zoomCentre();
  zoomAt(cx, cy, 1 / (window.devicePixelRatio || 1) / view.s);
}

function panBy(dx, dy) {
  view.ox += dx;
  view.oy += dy;
  view.fit = false;
  clampPan();
  placeImage();
}

function placeImage() {
  const f = state.frame;
  if (!f) return;
  const img = $("image");
  img.style.left = view.ox + "px";
  img.style.top = view.oy + "px";
  img.style.width = f.width * view.s + "px";
  img.style.height = f.height * view.s + "px";
  const dpr = window.devicePixelRatio || 1;
  $("zoom-value").textContent = (view.s * dpr >= 10 ? Math.round(view.s * dpr) : (view.s * dpr).toPrecision(2)) +
    "x" + (view.fit ? " (fit)" : "");
  drawOverlay();
}

// The image pixel under a pointer event, or null outside the image.
function pixelAt(ev) {
  const v = $("view"), r = v.getBoundingClientRect(), f = state.frame;
  const vx = ev.clientX - r.left - v.clientLeft, vy = ev.clientY - r.top - v.clientTop;
  const x = Math.floor((vx - view.ox) / view.s), y = Math.floor((vy - view.oy) / view.s);
  if (x < 0 || y < 0 || x >= f.width || y >= f.height) return null;
  return [x, y];
}

function viewPoint(ev) {
  const v = $("view"), r = v.getBoundingClientRect();
  return [ev.clientX - r.left - v.clientLeft, ev.clientY - r.top - v.clientTop];
}

// ---------------------------------------------------------------- overlay

function drawOverlay() {
  const f = state.frame, c = $("overlay");
  if (!f) return;
  const [w, h] = viewSize(), dpr = window.devicePixelRatio || 1;
  if (c.width !== Math.round(w * dpr) || c.height !== Math.round(h * dpr)) {
    c.width = Math.round(w * dpr);
    c.height = Math.round(h * dpr);
    c.style.width = w + "px";
    c.style.height = h + "px";
  }
  const g = c.getContext("2d");
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  g.clearRect(0, 0, w, h);
  const s = view.s, X = (x) => view.ox + x * s, Y = (y) => view.oy + y * s;
  // The visible range of image pixels.
  const x0 = Math.max(0, Math.floor(-view.ox / s)), x1 = Math.min(f.width, Math.ceil((w - view.ox) / s));
  const y0 = Math.max(0, Math.floor(-view.oy / s)), y1 = Math.min(f.height, Math.ceil((h - view.oy) / s));
  if (s * dpr >= GRID_ZOOM) {
    g.strokeStyle = "rgba(128,128,128,0.45)";
    g.lineWidth = 1 / dpr;
    g.beginPath();
    for (let x = x0; x <= x1; ++x) { g.moveTo(X(x), Y(y0)); g.lineTo(X(x), Y(y1)); }
    for (let y = y0; y <= y1; ++y) { g.moveTo(X(x0), Y(y)); g.lineTo(X(x1), Y(y)); }
    g.stroke();
  }
  if ($("grid").checked) {
    g.strokeStyle = "rgba(255,255,255,0.5)";
    g.lineWidth = 1;
    g.beginPath();
    for (let x = 0; x <= f.width; x += f.tile_size) { g.moveTo(X(x), Y(0)); g.lineTo(X(x), Y(f.height)); }
    for (let y = 0; y <= f.height; y += f.tile_size) { g.moveTo(X(0), Y(y)); g.lineTo(X(f.width), Y(y)); }
    g.stroke();
  }
  if (state.tile) {
    g.strokeStyle = "#ff0";
    g.lineWidth = 2;
    const tx = state.tile[0] * f.tile_size, ty = state.tile[1] * f.tile_size;
    const tw = Math.min(f.width, tx + f.tile_size) - tx, th = Math.min(f.height, ty + f.tile_size) - ty;
    g.strokeRect(X(tx), Y(ty), tw * s, th * s);
  }
  // The box first: the triangle's outline is drawn over it, never hidden.
  if (state.selected) drawBox(g, state.selected);
  if (state.tri) {
    g.lineWidth = 1.5;
    g.strokeStyle = "#0ff";
    for (const p of state.tri.pieces) {
      if (!p.window) continue;
      g.beginPath();
      p.window.forEach((v, i) => (i ? g.lineTo(X(v[0]), Y(v[1])) : g.moveTo(X(v[0]), Y(v[1]))));
      g.closePath();
      g.stroke();
    }
  }
}

// A hollow box around the pixel (at least 9 px across) with ticks pointing
// at it from outside: the pixel itself stays visible.
function drawBox(g, p) {
  const s = view.s, cx = view.ox + (p[0] + 0.5) * s, cy = view.oy + (p[1] + 0.5) * s;
  const half = Math.max(4.5, s / 2 + 2);
  const ticks = (ctx) => {
    ctx.beginPath();
    ctx.rect(cx - half, cy - half, 2 * half, 2 * half);
    ctx.moveTo(cx - half - 7, cy); ctx.lineTo(cx - half - 1, cy);
    ctx.moveTo(cx + half + 1, cy); ctx.lineTo(cx + half + 7, cy);
    ctx.moveTo(cx, cy - half - 7); ctx.lineTo(cx, cy - half - 1);
    ctx.moveTo(cx, cy + half + 1); ctx.lineTo(cx, cy + half + 7);
    ctx.stroke();
  };
  g.lineWidth = 2.5;
  g.strokeStyle = "rgba(0,0,0,0.7)";
  ticks(g);
  g.lineWidth = 1;
  g.strokeStyle = "#f0f";
  ticks(g);
}

// ---------------------------------------------------------------- legend and values

function el(tag, cls, text) {
  const e = document.createElement(tag);
  if (cls) e.className = cls;
  if (text !== undefined) e.textContent = text;
  return e;
}

function currentScale() {
  if (state.upto !== null) return null;
  const st = state.stages[state.stage];
  return st && st.scale ? st.scale : null;
}

function showLegend() {
  const box = $("legend"), sc = currentScale();
  box.textContent = "";
  if (!sc || sc.kind === "picture") return;
  const lg = el("div", "legend");
  lg.id = "legend-" + state.stage;
  lg.appendChild(el("div", "quantity", sc.quantity + (sc.units ? " (" + sc.units + ")" : "")));
  if (sc.kind === "ramp") {
    const bar = el("div", "bar");
    bar.style.background = "linear-gradient(to right, " +
      sc.stops.map(([t, c]) => c + " " + (t * 100) + "%").join(", ") + ")";
    lg.appendChild(bar);
    const ticks = el("div", "ticks");
    for (const [t, label] of sc.ticks) {
      const sp = el("span", t < 0.05 ? "start" : t > 0.95 ? "end" : "", label);
      sp.style.left = (t * 100) + "%";
      ticks.appendChild(sp);
    }
    lg.appendChild(ticks);
  } else if (sc.kind === "channels") {
    ["#ff0000", "#00ff00", "#0000ff"].forEach((hue, k) => {
      if (k >= sc.channels.length) return;
      const ch = el("span", "channel");
      ch.appendChild(el("span", "name", sc.channels[k]));
      const bar = el("span", "bar");
      bar.style.background = "linear-gradient(to right, #000000, " + hue + ")";
      ch.appendChild(bar);
      ch.appendChild(el("span", "", sc.min + " .. " + sc.max));
      lg.appendChild(ch);
    });
    lg.appendChild(el("span", "", sc.srgb ? "(sRGB-encoded)" : "(linear)"));
  }
  if (sc.classes.length) {
    const cl = el("div", "classes");
    for (const [c, label] of sc.classes) {
      const sp = el("span");
      const sw = el("i");
      sw.style.background = c;
      sp.appendChild(sw);
      sp.appendChild(document.createTextNode(label));
      cl.appendChild(sp);
    }
    lg.appendChild(cl);
  }
  box.appendChild(lg);
}

const hex = (rgb) => "#" + rgb.map((v) => v.toString(16).padStart(2, "0")).join("");
const srgbToLinear = (v) => (v <= 0.04045 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4));

function rampColour(sc, t) {
  const stops = sc.stops;
  let i = 0;
  while (i + 2 < stops.length && t > stops[i + 1][0]) ++i;
  const [t0, c0] = stops[i], [t1, c1] = stops[i + 1];
  const u = t1 > t0 ? Math.min(1, Math.max(0, (t - t0) / (t1 - t0))) : 0;
  const a = parseInt(c0.slice(1), 16), b = parseInt(c1.slice(1), 16);
  return [16, 8, 0].map((sh) => ((a >> sh) & 255) * (1 - u) + ((b >> sh) & 255) * u);
}

function rampValue(sc, t) {
  if (sc.map === "log") return Math.pow(2, Math.log2(sc.min) + t * (Math.log2(sc.max) - Math.log2(sc.min)));
  if (sc.map === "log1p") return Math.pow(1 + sc.max, t) - 1;
  if (sc.map === "x/(1+x)") return t < 1 ? t / (1 - t) : Infinity;
  return sc.min + t * (sc.max - sc.min);
}

// What the stage's scale says a displayed colour means ("" when nothing).
function readScale(sc, rgb) {
  if (!sc) return "";
  const h = hex(rgb);
  for (const [c, label] of sc.classes) if (c === h) return label;
  if (sc.kind === "ramp") {
    let best = 1e9, bt = 0;
    for (let i = 0; i <= 1024; ++i) {
      const c = rampColour(sc, i / 1024);
      const d = (c[0] - rgb[0]) ** 2 + (c[1] - rgb[1]) ** 2 + (c[2] - rgb[2]) ** 2;
      if (d < best) { best = d; bt = i / 1024; }
    }
    if (best > 48) return "not on the scale";
    const v = rampValue(sc, bt);
    return "about " + (isFinite(v) ? v.toPrecision(3) : "infinity") + (sc.units ? " " + sc.units : "") +
      " (read from the colour bar)";
  }
  if (sc.kind === "channels") {
    return sc.channels.map((name, k) => {
      const u = sc.srgb ? srgbToLinear(rgb[k] / 255) : rgb[k] / 255;
      return name + " " + (sc.min + u * (sc.max - sc.min)).toFixed(3);
    }).join(", ") + " (from the 8-bit colour)";
  }
  return "";
}

// The pixel under the pointer (else the selected one): coordinates, the
// displayed colour read back from the PNG, and what the legend makes of it.
function showValue() {
  const p = state.hover || state.selected, out = $("cursor-value");
  if (!p) { out.textContent = "move the pointer over the image"; return; }
  let text = (state.hover ? "" : "selected ") + "x " + p[0] + " y " + p[1];
  if (pixels.ready && p[0] < pixels.canvas.width && p[1] < pixels.canvas.height) {
    const d = pixels.ctx.getImageData(p[0], p[1], 1, 1).data, rgb = [d[0], d[1], d[2]];
    text += "  displayed colour (" + rgb.join(", ") + ") " + hex(rgb);
    const meaning = readScale(currentScale(), rgb);
    if (meaning) text += "  = " + meaning;
  }
  out.textContent = text;
}

// ---------------------------------------------------------------- panels

function triLink(n) {
  const a = el("a", "tri", "tri " + n);
  a.addEventListener("click", () => showTriangle(n, true));
  return a;
}

// Scrolls the right column (only it) so that the panel's top shows.
function revealPanel(id) {
  const panel = $(id), right = $("right");
  panel.open = true;
  const d = panel.getBoundingClientRect().top - right.getBoundingClientRect().top;
  right.scrollTop += d - 4;
}

// Which point of the frame the shown explanation is of.
function updatePixelNote() {
  const f = state.frame, note = $("pixel-note");
  if (!state.pixel) { note.textContent = ""; return; }
  note.textContent = state.pixelUpto !== null
    ? "Explained as the frame stands after the first " + state.pixelUpto + " of " + f.triangles +
      " triangles (the slider's point): the fragments of those triangles, the framebuffer's value then."
    : "Explained at the end of the frame (all " + f.triangles + " triangles).";
  if (state.pixelUpto !== state.upto) note.textContent += " Updating to the slider's point...";
}

// The explained pixel follows the slider (and a stage switch, which ends it).
function reexplain() {
  if (state.pixel && state.pixelUpto !== state.upto) showPixel(state.pixel[0], state.pixel[1]);
}

let pixelRequest = 0;
async function showPixel(x, y) {
  const ticket = ++pixelRequest;
  state.selected = [x, y];
  drawOverlay();
  try {
    const upto = state.upto;
    const p = await api("/api/pixel?x=" + x + "&y=" + y + (upto !== null ? "&upto=" + upto : ""));
    if (ticket !== pixelRequest) return;
    state.pixel = [x, y];
    state.pixelUpto = p.upto;
    $("pixel-coords").textContent = x + " " + y;
    const body = $("history").querySelector("tbody");
    body.textContent = "";
    p.history.forEach((h, i) => {
      const tr = document.createElement("tr");
      const cells = [String(i + 1), null, h.mesh, h.cover, h.pass, h.depth.toPrecision(7), h.result,
                     h.out ? "(" + h.out.map((v) => v.toPrecision(6)).join(", ") + ")" : ""];
      cells.forEach((c, k) => {
        const td = document.createElement("td");
        if (k === 1) td.appendChild(triLink(h.tri)); else td.textContent = c;
        tr.appendChild(td);
      });
      body.appendChild(tr);
    });
    showSamples(p);
    $("pixel-text").textContent = p.text;
    updatePixelNote();
    status("");
  } catch (e) { showError(e); }
}

// The pixel's samples: where each lies in the pixel (the square), which
// fragment of the history it ends the frame with, and its colour alone.
function showSamples(p) {
  const body = $("samples").querySelector("tbody");
  body.textContent = "";
  const c = $("sample-view"), g = c.getContext("2d"), n = c.width;
  g.fillStyle = "#000";
  g.fillRect(0, 0, n, n);
  g.strokeStyle = "#555";
  g.strokeRect(0.5, 0.5, n - 1, n - 1);
  p.sample_list.forEach((s, k) => {
    const rgb = "rgb(" + s.srgb8.join(",") + ")";
    const holds = s.owner < 0 ? "cleared" : "#" + (s.owner + 1) + " (tri " + p.history[s.owner].tri + ")";
    const tr = document.createElement("tr");
    const offset = "(" + s.offset[0] + ", " + s.offset[1] + ")";
    [String(k), offset, holds, s.depth.toPrecision(7)].forEach((t) => tr.appendChild(el("td", "", t)));
    const td = document.createElement("td");
    const sw = el("span", "swatch");
    sw.style.background = rgb;
    td.appendChild(sw);
    td.appendChild(document.createTextNode("(" + s.color.map((v) => v.toPrecision(6)).join(", ") + ")"));
    tr.appendChild(td);
    body.appendChild(tr);
    const x = (0.5 + s.offset[0]) * n, y = (0.5 + s.offset[1]) * n;
    g.fillStyle = rgb;
    g.strokeStyle = "#fff";
    g.beginPath();
    g.arc(x, y, n / 14, 0, 2 * Math.PI);
    g.fill();
    g.stroke();
    g.fillStyle = "#fff";
    g.font = "10px sans-serif";
    g.fillText("s" + k, x > n * 0.7 ? x - n / 12 - 12 : x + n / 12, y + 4);  // inside the square
  });
}

async function showTile(tx, ty) {
  try {
    const t = await api("/api/tile?x=" + tx + "&y=" + ty);
    state.tile = [tx, ty];
    drawOverlay();
    $("tile-coords").textContent = tx + " " + ty;
    $("tile-text").textContent = t.text;
    status("");
  } catch (e) { showError(e); }
}

async function showTriangle(n, reveal) {
  $("tri").value = n;
  try {
    state.tri = await api("/api/tri?n=" + n);
    $("tri-coords").textContent = String(n);
    $("tri-text").textContent = state.tri.text;
    status("");
    if (reveal) revealPanel("tri-panel");
  } catch (e) { showError(e); }
  drawOverlay();
}

function explain(x, y) {
  const ts = state.frame.tile_size;
  if ($("mode").value === "tile") {
    state.selected = [x, y];
    showTile(Math.floor(x / ts), Math.floor(y / ts));
  } else {
    showPixel(x, y);
    showTile(Math.floor(x / ts), Math.floor(y / ts));
  }
}

// ---------------------------------------------------------------- views: draws and textures

// A table row that selects: cells as text, a click calls `pick`.
function pickRow(cells, pick) {
  const tr = el("tr", "pick");
  for (const c of cells) tr.appendChild(typeof c === "string" ? el("td", "", c) : c);
  tr.addEventListener("click", () => pick(tr));
  return tr;
}

function choose(tbody, tr) {
  for (const r of tbody.children) r.classList.toggle("chosen", r === tr);
}

const panelError = (id, e) => { $(id).textContent = "error: " + e.message; };

// Each list loads when its panel first opens, so the page's load stays as before.
const views = { draws: null, textures: null, vertices: null, texture: null, texView: null, zoom: "fit" };

async function loadDraws() {
  if (views.draws) return;
  try {
    views.draws = (await api("/api/draws")).draws;
  } catch (e) { panelError("draw-text", e); return; }
  $("draws-count").textContent = "(" + views.draws.length + ")";
  const body = $("draws").querySelector("tbody");
  body.textContent = "";
  for (const d of views.draws) {
    const prims = d.topology === "triangles" ? String(d.primitives) : d.primitives + " " + d.topology;
    body.appendChild(pickRow([String(d.draw), d.mesh_name, d.material_name, prims, d.alpha,
                              el("td", d.visible ? "" : "culled", d.visible ? "visible" : "culled")],
                             (tr) => { choose(body, tr); showDraw(d.draw); }));
  }
}

async function showDraw(n) {
  const links = $("draw-links");
  try {
    const d = await api("/api/draw?n=" + n);
    $("draw-text").textContent = d.text;
    links.textContent = "";
    const a = el("a", "tri", "its vertices");
    a.addEventListener("click", () => showVertices(n, 0));
    links.appendChild(a);
    links.appendChild(document.createTextNode(" (" + d.mesh_name + ", " + d.program + ")"));
  } catch (e) { links.textContent = ""; panelError("draw-text", e); }
}

const VERTEX_ROWS = 16;
async function showVertices(n, first) {
  $("vertices-box").hidden = false;
  try {
    const v = await api("/api/vertices?draw=" + n + "&first=" + first + "&count=" + VERTEX_ROWS);
    views.vertices = { draw: n, first: first, count: v.vertex_count };
    const last = first + v.vertices.length;
    $("vertices-title").textContent = "draw " + n + ": vertices " + first + ".." + (last - 1) + " of " + v.vertex_count;
    $("vertices-more").disabled = last >= v.vertex_count;
    $("vertices-text").textContent = v.text;
  } catch (e) { $("vertices-more").disabled = true; panelError("vertices-text", e); }
}

async function loadTextures() {
  if (views.textures) return;
  try {
    views.textures = (await api("/api/textures")).textures;
  } catch (e) { panelError("texture-text", e); return; }
  const body = $("textures").querySelector("tbody");
  body.textContent = "";
  for (const t of views.textures) {
    const tr = pickRow([t.id, t.kind, t.width + "x" + t.height, String(t.levels), t.format.split(";")[0]],
                       (row) => { choose(body, row); pickTexture(t, 0); });
    tr.dataset.id = t.id;
    tr.title = t.format;
    body.appendChild(tr);
  }
}

function pickTexture(t, level) {
  views.texture = t;
  const sel = $("texture-level");
  sel.textContent = "";
  for (const l of t.level_sizes) {
    const o = el("option", "", "level " + l.level + " (" + l.width + "x" + l.height + ")");
    o.value = String(l.level);
    sel.appendChild(o);
  }
  sel.value = String(level);
  $("texture-name").textContent = t.id;
  const uses = $("texture-uses");
  uses.textContent = "";
  for (const u of t.images.concat(t.uses)) uses.appendChild(el("li", "", u));
  showTexture();
}

// The level's metadata first, then its PNG (loaded aside, swapped in when it arrived).
let textureRequest = 0;
async function showTexture() {
  const t = views.texture, level = Number($("texture-level").value), ticket = ++textureRequest;
  let v;
  try {
    v = await api("/api/texture?id=" + encodeURIComponent(t.id) + "&level=" + level);
  } catch (e) { panelError("texture-text", e); return; }
  if (ticket !== textureRequest) return;
  texelView.pinned = null;
  $("texel-text").hidden = true;
  texelView.hover = [-1, -1];
  hoverTexel(null);
  const size = v.level_sizes[level];
  $("texture-line").textContent = "texture " + v.id + ", level " + level + " of " + v.levels + ": " + size.width +
    "x" + size.height + ", " + v.format + (v.note ? "; " + v.note : "") + ". Shown as: " + v.png_rule + ".";
  $("texture-text").textContent = v.text;
  const url = v.png.endpoint + "?id=" + encodeURIComponent(v.png.id) + "&level=" + v.png.level;
  const loader = new Image();
  loader.onload = () => {
    if (ticket !== textureRequest) return;
    views.texView = { width: loader.naturalWidth, height: loader.naturalHeight };
    $("texture-image").src = url;
    $("texture-view").classList.remove("empty");
    showChannel(loader);
  };
  loader.onerror = () => {
    if (ticket === textureRequest) $("texture-text").textContent = "error: the image " + url + " could not be drawn";
  };
  loader.src = url;
}

// RGB shows the PNG itself; one channel is drawn as grey into the canvas.
function showChannel(source) {
  const img = $("texture-image"), c = $("texture-canvas"), ch = $("texture-channel").value;
  if (!views.texView) return;
  img.hidden = ch !== "rgb";
  c.hidden = ch === "rgb";
  if (ch !== "rgb") {
    const { width, height } = views.texView, k = "rgba".indexOf(ch);
    c.width = width;
    c.height = height;
    const g = c.getContext("2d", { willReadFrequently: true });
    g.clearRect(0, 0, width, height);
    g.drawImage(source || img, 0, 0);
    const d = g.getImageData(0, 0, width, height), p = d.data;
    for (let i = 0; i < p.length; i += 4) {
      const v = p[i + k];
      p[i] = p[i + 1] = p[i + 2] = v;
      p[i + 3] = 255;
    }
    g.putImageData(d, 0, 0);
  }
  placeTexture();
}

// Zoom: "fit" (the whole level in the box, enlarged or not), 1 or 4 texels per device pixel.
function placeTexture() {
  const t = views.texView, box = $("texture-view");
  if (!t) return;
  const dpr = window.devicePixelRatio || 1;
  let s;
  if (views.zoom === "fit") {
    const maxH = parseFloat(getComputedStyle(box).maxHeight) || 384;
    s = Math.min((box.clientWidth || 300) / t.width, maxH / t.height);
  } else s = views.zoom / dpr;
  for (const e of [$("texture-image"), $("texture-canvas")]) {
    e.style.width = t.width * s + "px";
    e.style.height = t.height * s + "px";
  }
  for (const [id, z] of [["texture-fit", "fit"], ["texture-one", 1], ["texture-four", 4]])
    $(id).classList.toggle("on", views.zoom === z);
}

// The texel under the pointer: its coordinates at once, its values from
// /api/texel (one request at a time, then the latest texel asked for); a
// click keeps one, with the text `texel ID LEVEL X Y` prints.
const texelView = { hover: null, busy: false, pinned: null };

function texelAt(ev) {
  const t = views.texView;
  if (!t) return null;
  const e = $("texture-channel").value === "rgb" ? $("texture-image") : $("texture-canvas");
  const r = e.getBoundingClientRect();
  if (!r.width || !r.height) return null;
  const x = Math.floor((ev.clientX - r.left) / r.width * t.width);
  const y = Math.floor((ev.clientY - r.top) / r.height * t.height);
  if (x < 0 || y < 0 || x >= t.width || y >= t.height) return null;
  return [x, y];
}

function texelUrl(p) {
  return "/api/texel?id=" + encodeURIComponent(views.texture.id) + "&level=" + $("texture-level").value +
    "&x=" + p[0] + "&y=" + p[1];
}

const fmtValues = (names, values, bytes) =>
  names.map((n, k) => n + " " + (values[k] === null ? "inf" : bytes ? String(values[k]) : values[k].toPrecision(6))).join(", ");

function texelLine(v) {
  return "texel " + v.x + " " + v.y + (v.face ? " (face " + ["+X", "-X", "+Y", "-Y", "+Z", "-Z"][v.face.face] + " " +
    v.face.x + " " + v.face.y + ")" : "") + ": stored " + v.stored_type + " " +
    fmtValues(v.stored_names, v.stored, v.stored_type === "8-bit") + "  ->  linear " +
    fmtValues(v.linear_names, v.linear, false) + "  (shown as " + v.shown.join(" ") + ")";
}

const TEXEL_HINT = "move the pointer over the texture for a texel's stored and linear values; click to keep one";

async function hoverTexel(p) {
  const same = (a, b) => a && b && a[0] === b[0] && a[1] === b[1];
  const out = $("texel-value");
  if (same(p, texelView.hover)) return;  // the same texel: already shown or on its way
  texelView.hover = p;
  if (!p) { out.textContent = views.texView ? TEXEL_HINT : ""; return; }
  out.textContent = "texel " + p[0] + " " + p[1] + " ...";
  if (texelView.busy) return;
  texelView.busy = true;
  try {
    for (;;) {
      const q = texelView.hover;
      if (!q) break;
      const v = await api(texelUrl(q));
      if (same(texelView.hover, q)) { out.textContent = texelLine(v); break; }
    }
  } catch (e) { out.textContent = "error: " + e.message; }
  texelView.busy = false;
}

async function pinTexel(p) {
  if (!p) return;
  texelView.pinned = p;
  try {
    const v = await api(texelUrl(p));
    if (texelView.pinned !== p) return;
    $("texel-text").textContent = v.text;
    $("texel-text").hidden = false;
  } catch (e) { $("texel-text").textContent = "error: " + e.message; $("texel-text").hidden = false; }
}

// ---------------------------------------------------------------- input

const drag = { down: false, moved: false, x: 0, y: 0, id: null };

function onPointerDown(ev) {
  if (!state.frame || ev.button !== 0) return;
  drag.down = true;
  drag.moved = false;
  drag.x = ev.clientX;
  drag.y = ev.clientY;
  drag.id = ev.pointerId;
  $("view").setPointerCapture(ev.pointerId);
  $("view").focus({ preventScroll: true });
}

function onPointerMove(ev) {
  if (!state.frame) return;
  if (drag.down) {
    const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
    if (!drag.moved && dx * dx + dy * dy > 16) {
      drag.moved = true;
      $("view").classList.add("dragging");
    }
    if (drag.moved) {
      drag.x = ev.clientX;
      drag.y = ev.clientY;
      panBy(dx, dy);
    }
  }
  state.hover = pixelAt(ev);
  showValue();
}

function onPointerUp(ev) {
  if (!drag.down) return;
  drag.down = false;
  $("view").classList.remove("dragging");
  if ($("view").hasPointerCapture(ev.pointerId)) $("view").releasePointerCapture(ev.pointerId);
  if (drag.moved) return;
  const p = pixelAt(ev);
  if (p) explain(p[0], p[1]);
}

function onWheel(ev) {
  if (!state.frame) return;
  ev.preventDefault();
  // One notch (100 px of deltaY) is a factor of sqrt(2); lines and pages count as notches.
  const delta = ev.deltaMode === 0 ? ev.deltaY : ev.deltaY * 100 / (ev.deltaMode === 1 ? 3 : 1);
  const [cx, cy] = viewPoint(ev);
  zoomAt(cx, cy, Math.pow(2, -delta / 200));
}

// Pans so that the selected pixel's box is inside the view.
function followSelected() {
  const [w, h] = viewSize(), p = state.selected, s = view.s, m = Math.max(12, s);
  const x = view.ox + (p[0] + 0.5) * s, y = view.oy + (p[1] + 0.5) * s;
  let dx = 0, dy = 0;
  if (x < m) dx = m - x; else if (x > w - m) dx = w - m - x;
  if (y < m) dy = m - y; else if (y > h - m) dy = h - m - y;
  if (dx || dy) panBy(dx, dy); else drawOverlay();
}

function onKey(ev) {
  if (!state.frame || ev.altKey || ev.ctrlKey || ev.metaKey) return;
  const f = state.frame, arrows = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1] };
  const [w, h] = viewSize();
  if (ev.key in arrows) {
    const [dx, dy] = arrows[ev.key];
    if (ev.shiftKey) panBy(-dx * w / 8, -dy * h / 8);
    else {
      const p = state.selected || [Math.floor(f.width / 2), Math.floor(f.height / 2)];
      state.selected = [Math.min(f.width - 1, Math.max(0, p[0] + dx)), Math.min(f.height - 1, Math.max(0, p[1] + dy))];
      state.hover = null;
      followSelected();
      showValue();
    }
  } else if (ev.key === "Enter") {
    if (state.selected) explain(state.selected[0], state.selected[1]);
  } else if (ev.key === "+" || ev.key === "=") zoomBy(2);
  else if (ev.key === "-" || ev.key === "_") zoomBy(0.5);
  else if (ev.key === "f" || ev.key === "F" || ev.key === "0") fitView();
  else if (ev.key === "1") oneToOne();
  else return;
  ev.preventDefault();
}

function onResize() {
  if (!state.frame) return;
  if (view.fit) fitView();
  else { clampPan(); placeImage(); }
}

// ---------------------------------------------------------------- start

async function start() {
  try {
    state.frame = await api("/api/frame");
    const stages = await api("/api/stages");
    const f = state.frame;
    $("summary").textContent = f.width + "x" + f.height + ", " + f.samples + " sample" + (f.samples > 1 ? "s" : "") +
      " per pixel, " + f.triangles + " triangles, " + f.draws + " draws, tiles of " + f.tile_size + ", recording " + (f.recording_bytes / 1048576).toFixed(1) + " MiB";
    $("frame-text").textContent = f.text;
    $("tri").max = f.triangles - 1;
    const sel = $("stage");
    for (const s of stages) {
      state.stages[s.name] = s;
      const o = document.createElement("option");
      o.value = s.name;
      o.textContent = s.title;
      sel.appendChild(o);
    }
    $("upto").max = f.triangles;
    showControls();
    fitView();
    showImage();
  } catch (e) {
    showError(e);
    if (!(e instanceof ServerGone)) status("cannot load the recording: " + e.message);
  }
}

const v = $("view");
v.addEventListener("pointerdown", onPointerDown);
v.addEventListener("pointermove", onPointerMove);
v.addEventListener("pointerup", onPointerUp);
v.addEventListener("pointercancel", onPointerUp);
v.addEventListener("pointerleave", () => { state.hover = null; showValue(); });
v.addEventListener("wheel", onWheel, { passive: false });
v.addEventListener("keydown", onKey);
new ResizeObserver(onResize).observe(v);
window.addEventListener("resize", () => views.zoom === "fit" && placeTexture());
$("fit").addEventListener("click", () => state.frame && fitView());
$("one").addEventListener("click", () => state.frame && oneToOne());
$("zoom-in").addEventListener("click", () => state.frame && zoomBy(2));
$("zoom-out").addEventListener("click", () => state.frame && zoomBy(0.5));
$("stage").addEventListener("change", () => {
  state.stage = $("stage").value;
  state.upto = null;
  showControls();
  showImage();
  reexplain();
});
let uptoTimer = null;
$("upto").addEventListener("input", () => {
  const n = Number($("upto").value);
  $("upto-value").textContent = n === Number($("upto").max) ? "all" : String(n);
  clearTimeout(uptoTimer);
  uptoTimer = setTimeout(() => {
    state.upto = n === Number($("upto").max) ? null : n;
    showControls();
    showImage();
    reexplain();
  }, 150);
});
$("grid").addEventListener("change", drawOverlay);
$("tri-go").addEventListener("click", () => showTriangle(Number($("tri").value), false));
$("tri").addEventListener("keydown", (ev) => { if (ev.key === "Enter") showTriangle(Number($("tri").value), false); });
$("draws-panel").addEventListener("toggle", () => { if ($("draws-panel").open) loadDraws(); });
$("vertices-more").addEventListener("click", () => {
  const v = views.vertices;
  if (v && v.first + VERTEX_ROWS < v.count) showVertices(v.draw, v.first + VERTEX_ROWS);
});
$("textures-panel").addEventListener("toggle", () => {
  if ($("textures-panel").open) { loadTextures(); placeTexture(); }
});
$("texture-level").addEventListener("change", () => views.texture && showTexture());
for (const id of ["texture-image", "texture-canvas"]) {
  $(id).addEventListener("pointermove", (ev) => hoverTexel(texelAt(ev)));
  $(id).addEventListener("pointerleave", () => hoverTexel(null));
  $(id).addEventListener("click", (ev) => pinTexel(texelAt(ev)));
}
$("texture-channel").addEventListener("change", () => showChannel(null));
$("texture-fit").addEventListener("click", () => { views.zoom = "fit"; placeTexture(); });
$("texture-one").addEventListener("click", () => { views.zoom = 1; placeTexture(); });
$("texture-four").addEventListener("click", () => { views.zoom = 4; placeTexture(); });
start();
