// The stepper's page: every number comes from the JSON API of the `step`
// process that served it (the same interpreter as the terminal front end).
"use strict";

const state = { frame: null, stage: "final", upto: null, pixel: null, tile: null, tri: null };
const $ = (id) => document.getElementById(id);

async function api(path) {
  const r = await fetch(path);
  const body = await r.json();
  if (!r.ok) throw new Error(body.error || r.statusText);
  return body;
}

function status(text) { $("status").textContent = text || ""; }

function imageUrl() {
  if (state.upto !== null) return "/api/upto?n=" + state.upto;
  return "/api/stage?name=" + encodeURIComponent(state.stage);
}

function showImage() {
  status("drawing...");
  $("image").src = imageUrl();
}

function drawOverlay() {
  const img = $("image"), c = $("overlay"), f = state.frame;
  if (!f) return;
  c.width = img.clientWidth;
  c.height = img.clientHeight;
  const sx = img.clientWidth / f.width, sy = img.clientHeight / f.height;
  const g = c.getContext("2d");
  g.clearRect(0, 0, c.width, c.height);
  if ($("grid").checked) {
    g.strokeStyle = "rgba(255,255,255,0.35)";
    g.beginPath();
    for (let x = 0; x <= f.width; x += f.tile_size) { g.moveTo(x * sx + 0.5, 0); g.lineTo(x * sx + 0.5, c.height); }
    for (let y = 0; y <= f.height; y += f.tile_size) { g.moveTo(0, y * sy + 0.5); g.lineTo(c.width, y * sy + 0.5); }
    g.stroke();
  }
  if (state.tile) {
    g.strokeStyle = "#ff0";
    g.lineWidth = 2;
    g.strokeRect(state.tile[0] * f.tile_size * sx, state.tile[1] * f.tile_size * sy, f.tile_size * sx, f.tile_size * sy);
    g.lineWidth = 1;
  }
  if (state.tri) {
    for (const p of state.tri.pieces) {
      if (!p.window) continue;
      g.strokeStyle = "#0ff";
      g.beginPath();
      p.window.forEach((v, i) => (i ? g.lineTo(v[0] * sx, v[1] * sy) : g.moveTo(v[0] * sx, v[1] * sy)));
      g.closePath();
      g.stroke();
    }
  }
  if (state.pixel) {
    const x = (state.pixel[0] + 0.5) * sx, y = (state.pixel[1] + 0.5) * sy;
    g.strokeStyle = "#f0f";
    g.beginPath();
    g.moveTo(x - 8, y); g.lineTo(x - 2, y); g.moveTo(x + 2, y); g.lineTo(x + 8, y);
    g.moveTo(x, y - 8); g.lineTo(x, y - 2); g.moveTo(x, y + 2); g.lineTo(x, y + 8);
    g.stroke();
  }
}

function triLink(n) {
  const a = document.createElement("a");
  a.className = "tri";
  a.textContent = "tri " + n;
  a.addEventListener("click", () => showTriangle(n));
  return a;
}

async function showPixel(x, y) {
  state.pixel = [x, y];
  $("pixel-coords").textContent = x + " " + y;
  try {
    const p = await api("/api/pixel?x=" + x + "&y=" + y);
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
    status("");
  } catch (e) { status(e.message); }
  drawOverlay();
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
    [String(k), offset, holds, s.depth.toPrecision(7)].forEach((t) => {
      const td = document.createElement("td");
      td.textContent = t;
      tr.appendChild(td);
    });
    const td = document.createElement("td");
    const sw = document.createElement("span");
    sw.className = "swatch";
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
    g.fillText("s" + k, x + n / 12, y + 4);
  });
}

async function showTile(tx, ty) {
  state.tile = [tx, ty];
  $("tile-coords").textContent = tx + " " + ty;
  try {
    const t = await api("/api/tile?x=" + tx + "&y=" + ty);
    $("tile-text").textContent = t.text;
    status("");
  } catch (e) { status(e.message); }
  drawOverlay();
}

async function showTriangle(n) {
  $("tri").value = n;
  try {
    state.tri = await api("/api/tri?n=" + n);
    $("tri-text").textContent = state.tri.text;
    status("");
  } catch (e) { state.tri = null; status(e.message); }
  drawOverlay();
}

function pixelAt(ev) {
  const img = $("image"), r = img.getBoundingClientRect(), f = state.frame;
  const x = Math.floor((ev.clientX - r.left - img.clientLeft) * f.width / img.clientWidth);
  const y = Math.floor((ev.clientY - r.top - img.clientTop) * f.height / img.clientHeight);
  return [Math.min(f.width - 1, Math.max(0, x)), Math.min(f.height - 1, Math.max(0, y))];
}

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
      const o = document.createElement("option");
      o.value = s.name;
      o.textContent = s.title;
      o.dataset.about = s.about;
      sel.appendChild(o);
    }
    sel.value = "final";
    $("stage-about").textContent = sel.selectedOptions[0].dataset.about;
    const up = $("upto");
    up.max = f.triangles;
    up.value = f.triangles;
    showImage();
  } catch (e) { status("cannot load the recording: " + e.message); }
}

$("image").addEventListener("load", () => { status(""); drawOverlay(); });
$("image").addEventListener("error", () => status("the image could not be drawn"));
$("image").addEventListener("click", (ev) => {
  if (!state.frame) return;
  const [x, y] = pixelAt(ev);
  if ($("mode").value === "tile") showTile(Math.floor(x / state.frame.tile_size), Math.floor(y / state.frame.tile_size));
  else { showPixel(x, y); showTile(Math.floor(x / state.frame.tile_size), Math.floor(y / state.frame.tile_size)); }
});
$("stage").addEventListener("change", () => {
  state.stage = $("stage").value;
  state.upto = null;
  $("upto").value = $("upto").max;
  $("upto-value").textContent = "all";
  $("stage-about").textContent = $("stage").selectedOptions[0].dataset.about;
  showImage();
});
let uptoTimer = null;
$("upto").addEventListener("input", () => {
  const n = Number($("upto").value);
  $("upto-value").textContent = n === Number($("upto").max) ? "all" : String(n);
  clearTimeout(uptoTimer);
  uptoTimer = setTimeout(() => {
    state.upto = n === Number($("upto").max) ? null : n;
    if (state.upto !== null) $("stage-about").textContent =
      "The frame after the first " + n + " triangles in submission order, drawn by the real pipeline.";
    showImage();
  }, 150);
});
$("grid").addEventListener("change", drawOverlay);
$("tri-go").addEventListener("click", () => showTriangle(Number($("tri").value)));
$("tri").addEventListener("keydown", (ev) => { if (ev.key === "Enter") showTriangle(Number($("tri").value)); });
window.addEventListener("resize", drawOverlay);
start();
