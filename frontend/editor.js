// The editor page: a canvas over the (rectified) photo. All changes go through commands and the history;
// a drag is previewed outside the history and committed as one command on pointerup.
import {AddRects, DeleteRects, ReplaceAll, UpdateRects, duplicateRects, moveRects, repeatRects, setLabel}
  from "./commands.js";
import {clampToImage, handleAt, handlePoints, intersects, moveWithin, normalize, resize, snap} from "./geometry.js";
import {History} from "./history.js";
import {HOTKEYS, LABELS, cssColor} from "./labels.js";
import {findSimilar, toGray} from "./match.js";
import {RectifyMode} from "./rectify-mode.js";
import {Segmentation} from "./state.js";

const $ = (sel) => document.querySelector(sel);
const root = $("#editor");
const photoCode = root.dataset.photo;
const csrf = document.querySelector("meta[name=csrf-token]").content;
const canvas = $("#canvas");
const ctx = canvas.getContext("2d");
const SNAP_PX = 6;  // screen pixels
const HANDLE_PX = 6;

const view = {scale: 1, ox: 0, oy: 0};  // screen = image * scale + offset
const ui = {tool: "draw", label: "window", selection: new Set(), drag: null, guides: [], proposals: [],
  space: false, overlay: null, overlayAlpha: 0.5};
let photo = null;  // HTMLImageElement
let seg = null;
let history = null;
let gray = null;
let info = null;  // the photo's API record
let rectifying = null;  // a RectifyMode while the rectification step is open

// --- loading --------------------------------------------------------------------------------------------------
async function api(path, options = {}) {
  const r = await fetch(path, {credentials: "same-origin", ...options,
    headers: {"X-CSRFToken": csrf, ...(options.body && !(options.body instanceof FormData)
      ? {"Content-Type": "application/json"} : {}), ...(options.headers || {})}});
  const body = r.headers.get("Content-Type")?.includes("json") ? await r.json() : null;
  if (!r.ok) throw new Error(body ? Object.entries(body).map(([k, v]) => `${k}: ${v}`).join("; ") : r.statusText);
  return body;
}

function status(text, kind = "") {
  const el = $("#status");
  el.textContent = text;
  el.className = `msg ${kind}`;
}

async function load() {
  info = await api(`/api/v1/photos/${photoCode}/`);
  photo = new Image();
  photo.src = info.rectified || info.image;
  await photo.decode();
  seg = new Segmentation(photo.naturalWidth, photo.naturalHeight);
  history = new History(seg);
  if (info.segmentation) {
    const saved = await api(`/api/v1/segmentations/${info.segmentation}/`);
    if (saved.data.width === seg.width && saved.data.height === seg.height) {
      history.execute(new ReplaceAll(Segmentation.fromJSON(saved.data).toJSON().rects));
      history.done = [];  // the loaded version is the starting point, not an undoable step
      history.markSaved();
    } else {
      root.dataset.segmentation = "";
      status(`The saved segmentation (${saved.data.width}x${saved.data.height}) was drawn before rectification; ` +
        "start a new one on the rectified photo.");
    }
  }
  const draft = localStorage.getItem(draftKey());
  if (draft) {
    const {json, when} = JSON.parse(draft);
    if (confirm(`Restore the unsaved changes from ${new Date(when).toLocaleString()}?`)) {
      history.execute(new ReplaceAll(Segmentation.fromJSON(json).toJSON().rects));
    } else {
      localStorage.removeItem(draftKey());
    }
  }
  history.onChange(changed);
  fit();
  buildPalette();
  changed();
}

function draftKey() { return `facaid-draft:${photoCode}`; }

function changed() {
  for (const id of [...ui.selection]) if (!seg.rects.has(id)) ui.selection.delete(id);
  if (history.dirty) {
    localStorage.setItem(draftKey(), JSON.stringify({json: seg.toJSON(), when: Date.now()}));  // autosave
  } else {
    localStorage.removeItem(draftKey());
  }
  $("#undo").disabled = !history.canUndo;
  $("#redo").disabled = !history.canRedo;
  $("#dirty").textContent = history.dirty ? "unsaved changes" : "saved";
  $("#count").textContent = `${seg.size} rectangles, ${ui.selection.size} selected`;
  draw();
}

function run(cmd) {
  try {
    history.execute(cmd);
  } catch (err) {
    status(err.message, "error");
  }
}

// --- view ---------------------------------------------------------------------------------------------------------
function fit() {
  const box = canvas.parentElement.getBoundingClientRect();
  canvas.width = box.width;
  canvas.height = Math.max(400, window.innerHeight - box.top - 24);
  view.scale = Math.min(canvas.width / seg.width, canvas.height / seg.height) * 0.95;
  view.ox = (canvas.width - seg.width * view.scale) / 2;
  view.oy = (canvas.height - seg.height * view.scale) / 2;
  draw();
}

const toImage = (sx, sy) => [(sx - view.ox) / view.scale, (sy - view.oy) / view.scale];
const sx = (x) => x * view.scale + view.ox;
const sy = (y) => y * view.scale + view.oy;

function strokeRect(r, color, width = 1, dash = []) {
  ctx.setLineDash(dash);
  ctx.strokeStyle = color;
  ctx.lineWidth = width;
  ctx.strokeRect(sx(r.x0) + 0.5, sy(r.y0) + 0.5, (r.x1 - r.x0) * view.scale, (r.y1 - r.y0) * view.scale);
  ctx.setLineDash([]);
}

function draw() {
  if (rectifying) return rectifying.draw();
  if (!seg) return;
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.fillStyle = "#2a2f36";
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  ctx.imageSmoothingEnabled = view.scale < 1;
  ctx.drawImage(photo, view.ox, view.oy, seg.width * view.scale, seg.height * view.scale);
  const preview = ui.drag?.preview || new Map();
  const alpha = Number($("#fill").value);
  for (const r0 of seg.paintOrder()) {
    const r = preview.get(r0.id) || r0;
    ctx.fillStyle = cssColor(r.label, alpha);
    ctx.fillRect(sx(r.x0), sy(r.y0), (r.x1 - r.x0) * view.scale, (r.y1 - r.y0) * view.scale);
    strokeRect(r, cssColor(r.label), 1);
  }
  if (ui.drag?.kind === "draw" && ui.drag.rect) {
    ctx.fillStyle = cssColor(ui.label, 0.4);
    const r = ui.drag.rect;
    ctx.fillRect(sx(r.x0), sy(r.y0), (r.x1 - r.x0) * view.scale, (r.y1 - r.y0) * view.scale);
    strokeRect(r, "#fff", 1, [4, 3]);
  }
  for (const id of ui.selection) {
    const r = preview.get(id) || seg.rects.get(id);
    if (!r) continue;
    strokeRect(r, "#fff", 2);
    if (ui.selection.size === 1) {
      ctx.fillStyle = "#fff";
      for (const [hx, hy] of Object.values(handlePoints(r))) ctx.fillRect(sx(hx) - 3, sy(hy) - 3, 7, 7);
    }
  }
  for (const p of ui.proposals) strokeRect(p, p.accepted === false ? "#888" : "#ffeb3b", 2, [6, 4]);
  if (ui.drag?.kind === "marquee") strokeRect(normalize(ui.drag.box), "#9cf", 1, [3, 3]);
  ctx.strokeStyle = "#ff4fd8";
  ctx.lineWidth = 1;
  for (const g of ui.guides) {
    ctx.beginPath();
    if (g.axis === "x") { ctx.moveTo(sx(g.at) + 0.5, 0); ctx.lineTo(sx(g.at) + 0.5, canvas.height); }
    else { ctx.moveTo(0, sy(g.at) + 0.5); ctx.lineTo(canvas.width, sy(g.at) + 0.5); }
    ctx.stroke();
  }
  if (ui.overlay) {
    ctx.globalAlpha = ui.overlayAlpha;
    ctx.drawImage(ui.overlay, view.ox, view.oy, seg.width * view.scale, seg.height * view.scale);
    ctx.globalAlpha = 1;
  }
}

// --- palette and tools --------------------------------------------------------------------------------------------
function buildPalette() {
  const box = $("#palette");
  box.replaceChildren();
  LABELS.forEach((label, i) => {
    const b = document.createElement("button");
    b.type = "button";
    b.dataset.label = label;
    b.innerHTML = `<span class="swatch" style="background:${cssColor(label)}"></span> ${label} <kbd>${HOTKEYS[i]}</kbd>`;
    b.addEventListener("click", () => pickLabel(label));
    box.append(b);
  });
  pickLabel(ui.label);
}

function pickLabel(label) {
  ui.label = label;
  for (const b of document.querySelectorAll("#palette button")) b.classList.toggle("active", b.dataset.label === label);
  // with the select tool the class goes to the selection; with the draw tool it is the class of the next one
  if (ui.tool === "select" && ui.selection.size) run(setLabel([...ui.selection], label));
}

function setTool(tool) {
  ui.tool = tool;
  for (const b of document.querySelectorAll("[data-tool]")) b.classList.toggle("active", b.dataset.tool === tool);
  canvas.style.cursor = tool === "draw" ? "crosshair" : "default";
}

// --- pointer --------------------------------------------------------------------------------------------------------
function others(ids) {
  return [...seg.rects.values()].filter((r) => !ids.has(r.id));
}

function snapped(rect, ids, edges, event) {
  if (event.altKey || !$("#snap").checked) return {rect, guides: []};
  return snap(rect, others(ids), SNAP_PX / view.scale, edges, seg);
}

// two fingers (or any two pointers) pinch to zoom and drag to pan; a gesture started by the first finger is dropped
const pointers = new Map();  // pointerId -> [offsetX, offsetY] while down
const clampScale = (s) => Math.max(0.05, Math.min(40, s));

function pinch() {
  const [[ax, ay], [bx, by]] = [...pointers.values()];
  return {mx: (ax + bx) / 2, my: (ay + by) / 2, dist: Math.hypot(bx - ax, by - ay) || 1};
}

function pinchStart() {
  const p = pinch();
  ui.drag = {kind: "pinch", dist: p.dist, scale: view.scale, anchor: toImage(p.mx, p.my)};
  ui.guides = [];
  draw();
}

function pinchMove(d) {
  const p = pinch();
  view.scale = clampScale(d.scale * p.dist / d.dist);
  view.ox = p.mx - d.anchor[0] * view.scale;
  view.oy = p.my - d.anchor[1] * view.scale;
  draw();
}

canvas.addEventListener("pointerdown", (e) => {
  canvas.setPointerCapture(e.pointerId);
  if (rectifying) return rectifying.pointerdown(e);
  pointers.set(e.pointerId, [e.offsetX, e.offsetY]);
  if (pointers.size === 2) return pinchStart();
  if (pointers.size > 2) return;
  const [x, y] = toImage(e.offsetX, e.offsetY);
  if (ui.space || e.button === 1) {
    ui.drag = {kind: "pan", sx: e.offsetX, sy: e.offsetY, ox: view.ox, oy: view.oy};
    return;
  }
  if (ui.selection.size === 1) {
    const id = [...ui.selection][0];
    const handle = handleAt(seg.get(id), x, y, HANDLE_PX / view.scale);
    if (handle) { ui.drag = {kind: "resize", id, handle, preview: new Map()}; return; }
  }
  if (ui.tool === "draw") {
    ui.drag = {kind: "draw", x0: x, y0: y, rect: null};
    return;
  }
  // a click inside the selection grabs it even where another class paints on top
  const inside = [...ui.selection].map((id) => seg.get(id)).find((r) => x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1);
  const hit = inside && !e.shiftKey ? inside : seg.topAt(x, y);
  if (hit) {
    if (e.shiftKey) {
      ui.selection.has(hit.id) ? ui.selection.delete(hit.id) : ui.selection.add(hit.id);
    } else if (!ui.selection.has(hit.id)) {
      ui.selection = new Set([hit.id]);
    }
    ui.drag = {kind: "move", x, y, ids: new Set(ui.selection), preview: new Map()};
  } else {
    if (!e.shiftKey) ui.selection.clear();
    ui.drag = {kind: "marquee", box: {x0: x, y0: y, x1: x, y1: y}};
  }
  changed();
});

canvas.addEventListener("pointermove", (e) => {
  if (rectifying) return rectifying.pointermove(e);
  if (pointers.has(e.pointerId)) pointers.set(e.pointerId, [e.offsetX, e.offsetY]);
  const d = ui.drag;
  if (!d) return;
  if (d.kind === "pinch") return pointers.size >= 2 && pinchMove(d);
  const [x, y] = toImage(e.offsetX, e.offsetY);
  ui.guides = [];
  if (d.kind === "pan") {
    view.ox = d.ox + e.offsetX - d.sx;
    view.oy = d.oy + e.offsetY - d.sy;
  } else if (d.kind === "draw") {
    const s = snapped({x0: d.x0, y0: d.y0, x1: x, y1: y}, new Set(), ["x1", "y1"], e);
    d.rect = normalize(s.rect);
    ui.guides = s.guides;
  } else if (d.kind === "move") {
    const dx = x - d.x, dy = y - d.y;
    // snap the bounding box of the selection, then move every member by the snapped offset
    const boxes = [...d.ids].map((id) => seg.get(id));
    const bbox = {x0: Math.min(...boxes.map((b) => b.x0)), y0: Math.min(...boxes.map((b) => b.y0)),
      x1: Math.max(...boxes.map((b) => b.x1)), y1: Math.max(...boxes.map((b) => b.y1))};
    const moved = moveWithin(bbox, dx, dy, seg.width, seg.height);
    const s = snapped(moved, d.ids, ["x0", "x1", "y0", "y1"], e);
    ui.guides = s.guides;
    d.dx = Math.round(s.rect.x0 - bbox.x0);
    d.dy = Math.round(s.rect.y0 - bbox.y0);
    d.preview = new Map(boxes.map((b) => [b.id, {...b, x0: b.x0 + d.dx, x1: b.x1 + d.dx, y0: b.y0 + d.dy, y1: b.y1 + d.dy}]));
  } else if (d.kind === "resize") {
    const r = seg.get(d.id);
    const edges = [];
    if (d.handle.includes("n")) edges.push("y0");
    if (d.handle.includes("s")) edges.push("y1");
    if (d.handle.includes("w")) edges.push("x0");
    if (d.handle.includes("e")) edges.push("x1");
    const resized = resize(r, d.handle, x, y);
    const s = snapped(resized, new Set([d.id]), edges, e);
    ui.guides = s.guides;
    const box = clampToImage(s.rect, seg.width, seg.height);
    d.preview = box ? new Map([[d.id, {...r, ...box}]]) : new Map();
  } else if (d.kind === "marquee") {
    d.box.x1 = x;
    d.box.y1 = y;
  }
  draw();
});

canvas.addEventListener("pointercancel", (e) => {
  pointers.delete(e.pointerId);
  if (rectifying) return;
  ui.drag = null;  // the browser took the gesture: nothing is committed
  ui.guides = [];
  draw();
});

canvas.addEventListener("pointerup", (e) => {
  pointers.delete(e.pointerId);
  if (rectifying) return rectifying.pointerup();
  const d = ui.drag;
  ui.drag = null;
  ui.guides = [];
  if (!d || d.kind === "pinch") return draw();
  if (d.kind === "draw" && d.rect) {
    const box = clampToImage(d.rect, seg.width, seg.height);
    if (box && box.x1 - box.x0 >= 2 && box.y1 - box.y0 >= 2) {
      const cmd = new AddRects([{label: ui.label, ...box}], "draw");
      run(cmd);
      if (cmd.ids) ui.selection = new Set(cmd.ids);
    }
  } else if (d.kind === "move" && (d.dx || d.dy)) {
    run(moveRects(seg, [...d.ids], d.dx, d.dy));
  } else if (d.kind === "resize" && d.preview.size) {
    const r = d.preview.get(d.id);
    run(new UpdateRects([{id: d.id, after: {x0: r.x0, y0: r.y0, x1: r.x1, y1: r.y1}}], "resize"));
  } else if (d.kind === "marquee") {
    const box = normalize(d.box);
    for (const r of seg.rects.values()) if (intersects(r, box) && r.label !== "facade") ui.selection.add(r.id);
  }
  changed();
});

canvas.addEventListener("wheel", (e) => {
  e.preventDefault();
  const [x, y] = toImage(e.offsetX, e.offsetY);
  view.scale = clampScale(view.scale * Math.exp(-e.deltaY * 0.0015));
  view.ox = e.offsetX - x * view.scale;
  view.oy = e.offsetY - y * view.scale;
  draw();
}, {passive: false});

// --- keyboard ---------------------------------------------------------------------------------------------------
window.addEventListener("keydown", (e) => {
  if (e.target.closest("input, textarea, select")) return;
  const key = e.key;
  const mod = e.ctrlKey || e.metaKey;
  if (key === " ") { ui.space = true; canvas.style.cursor = "grab"; e.preventDefault(); return; }
  if (mod && key.toLowerCase() === "z") { e.shiftKey ? history.redo() : history.undo(); e.preventDefault(); return; }
  if (mod && key.toLowerCase() === "y") { history.redo(); e.preventDefault(); return; }
  if (mod && key.toLowerCase() === "d") { duplicate(); e.preventDefault(); return; }
  if (mod && key.toLowerCase() === "a") { ui.selection = new Set(seg.rects.keys()); changed(); e.preventDefault(); return; }
  if (mod) return;
  if (key === "Delete" || key === "Backspace") { removeSelected(); e.preventDefault(); return; }
  if (key === "Escape") { ui.selection.clear(); ui.proposals = []; changed(); return; }
  if (key === "r") return setTool("draw");
  if (key === "v") return setTool("select");
  if (key === "Enter" && ui.proposals.length) return acceptProposals();
  const i = HOTKEYS.indexOf(key);
  if (i >= 0) return pickLabel(LABELS[i]);
  const arrows = {ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1]};
  if (arrows[key] && ui.selection.size) {
    const step = e.shiftKey ? 10 : 1;
    run(moveRects(seg, [...ui.selection], arrows[key][0] * step, arrows[key][1] * step));
    e.preventDefault();
  }
});
window.addEventListener("keyup", (e) => {
  if (e.key === " ") { ui.space = false; setTool(ui.tool); }
});

function removeSelected() {
  if (ui.selection.size) run(new DeleteRects([...ui.selection]));
}

function duplicate() {
  if (!ui.selection.size) return;
  const cmd = duplicateRects(seg, [...ui.selection], 10, 10);
  run(cmd);
  if (cmd.ids) ui.selection = new Set(cmd.ids);
  changed();
}

// --- repeat and find similar -----------------------------------------------------------------------------------
function repeatSelected() {
  if (ui.selection.size !== 1) return status("Select one rectangle to repeat.", "error");
  const id = [...ui.selection][0];
  const r = seg.get(id);
  const cols = Number($("#rep-cols").value), rows = Number($("#rep-rows").value);
  const gapX = Number($("#rep-gapx").value), gapY = Number($("#rep-gapy").value);
  try {
    run(repeatRects(seg, id, {cols, rows, dx: r.x1 - r.x0 + gapX, dy: r.y1 - r.y0 + gapY}));
  } catch (err) {
    status(err.message, "error");
  }
}

function similar() {
  if (ui.selection.size !== 1) return status("Select one drawn rectangle to look for copies of it.", "error");
  const r = seg.get([...ui.selection][0]);
  if (!gray) {
    const c = document.createElement("canvas");
    c.width = seg.width;
    c.height = seg.height;
    const g = c.getContext("2d", {willReadFrequently: true});
    g.drawImage(photo, 0, 0);
    gray = toGray(g.getImageData(0, 0, seg.width, seg.height));
  }
  const same = [...seg.rects.values()].filter((o) => o.label === r.label && o.id !== r.id);
  ui.proposals = findSimilar(gray, r, {threshold: Number($("#sim-threshold").value), exclude: same})
    .map((p) => ({...p, label: r.label}));
  status(ui.proposals.length ? `${ui.proposals.length} proposals: click one to reject it, Enter or "Accept" to add the rest.`
    : "No similar places found.");
  draw();
}

function acceptProposals() {
  const keep = ui.proposals.filter((p) => p.accepted !== false);
  ui.proposals = [];
  if (keep.length) run(new AddRects(keep.map(({label, x0, y0, x1, y1}) => ({label, x0, y0, x1, y1})), "find similar"));
  changed();
}

canvas.addEventListener("click", (e) => {
  if (!ui.proposals.length) return;
  const [x, y] = toImage(e.offsetX, e.offsetY);
  const p = ui.proposals.find((q) => x >= q.x0 && x < q.x1 && y >= q.y0 && y < q.y1);
  if (p) { p.accepted = p.accepted === false; draw(); }
}, true);

// --- files, saving, submitting ------------------------------------------------------------------------------------
function exportJSON() {
  const blob = new Blob([JSON.stringify(seg.toJSON(), null, 1)], {type: "application/json"});
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = `segmentation-${photoCode.slice(0, 8)}.json`;
  a.click();
  URL.revokeObjectURL(a.href);
}

async function importJSON(file) {
  try {
    const parsed = Segmentation.fromJSON(JSON.parse(await file.text()));
    if (parsed.width !== seg.width || parsed.height !== seg.height) {
      throw new Error(`the file is ${parsed.width}x${parsed.height}; the photo is ${seg.width}x${seg.height}`);
    }
    run(new ReplaceAll(parsed.toJSON().rects));
    status(`Imported ${parsed.size} rectangles.`, "success");
  } catch (err) {
    status(`Not imported: ${err.message}`, "error");
  }
}

async function save() {
  const body = await api(`/api/v1/photos/${photoCode}/segmentations/`, {method: "POST", body: JSON.stringify(seg.toJSON())});
  history.markSaved();
  status(`Saved as version ${body.version}.`, "success");
  return body;
}

async function submit() {
  try {
    const saved = history.dirty || !root.dataset.segmentation ? await save() : {code: root.dataset.segmentation};
    root.dataset.segmentation = saved.code;
    const job = await api("/api/v1/jobs/", {method: "POST", body: JSON.stringify({segmentation: saved.code, k: 4})});
    $("#job").hidden = false;
    poll(job.code);
  } catch (err) {
    status(`Not submitted: ${err.message}`, "error");
  }
}

async function poll(code) {
  const job = await api(`/api/v1/jobs/${code}/`);
  const stage = job.status === "running" && job.stage ? ` (${job.stage})` : "";  // not "done (done)"
  $("#job-status").textContent = `${job.status}${stage}`;
  $("#job-progress").value = job.progress;
  if (job.status === "queued" || job.status === "running") return setTimeout(() => poll(code), 1000);
  if (job.status === "failed") return status(`The reconstruction failed: ${job.message}`, "error");
  const img = new Image();
  img.src = `/api/v1/procedures/${job.result}/download/labels.png`;
  await img.decode();
  ui.overlay = img;
  $("#result-link").href = `/procedures/${job.result}`;
  $("#result").hidden = false;
  draw();
}

// --- rectification ------------------------------------------------------------------------------------------------
async function openRectify() {
  const original = new Image();
  original.src = info.image;
  await original.decode();
  rectifying = new RectifyMode({canvas, preview: $("#rectify-preview"), image: original, corners: info.corners});
  $("#rectify-panel").hidden = false;
  rectifying.draw();
  rectifying.renderPreview();
  status("Drag the four corners onto the facade's corners; the preview shows the result.");
}

function closeRectify() {
  rectifying = null;
  $("#rectify-panel").hidden = true;
  draw();
}

async function applyRectify() {
  if (seg.size && !confirm("Rectifying changes the image: the rectangles drawn so far do not carry over. Go on?")) return;
  try {
    await api(`/api/v1/photos/${photoCode}/rectify`, {method: "POST", body: JSON.stringify({corners: rectifying.corners})});
    history.markSaved();
    localStorage.removeItem(draftKey());
    location.reload();
  } catch (err) {
    status(`Not rectified: ${err.message}`, "error");
  }
}

// --- wiring -----------------------------------------------------------------------------------------------------
for (const b of document.querySelectorAll("[data-tool]")) b.addEventListener("click", () => setTool(b.dataset.tool));
$("#undo").addEventListener("click", () => history.undo());
$("#redo").addEventListener("click", () => history.redo());
$("#delete").addEventListener("click", removeSelected);
$("#duplicate").addEventListener("click", duplicate);
$("#repeat").addEventListener("click", repeatSelected);
$("#similar").addEventListener("click", similar);
$("#accept").addEventListener("click", acceptProposals);
$("#export").addEventListener("click", exportJSON);
$("#import").addEventListener("change", (e) => e.target.files[0] && importJSON(e.target.files[0]));
$("#save").addEventListener("click", () => save().catch((err) => status(`Not saved: ${err.message}`, "error")));
$("#submit").addEventListener("click", submit);
$("#fill").addEventListener("input", draw);
$("#overlay-alpha").addEventListener("input", (e) => { ui.overlayAlpha = Number(e.target.value); draw(); });
$("#rectify").addEventListener("click", openRectify);
$("#rectify-apply").addEventListener("click", applyRectify);
$("#rectify-cancel").addEventListener("click", closeRectify);
window.addEventListener("resize", fit);
window.addEventListener("beforeunload", (e) => {
  if (history?.dirty) { e.preventDefault(); e.returnValue = ""; }
});
setTool("draw");
load().catch((err) => status(`Could not load the photo: ${err.message}`, "error"));

// for tests and the console
window.facaidEditor = {get seg() { return seg; }, get history() { return history; }, get rectifying() { return rectifying; },
  ui, view};
