// The editor page: the glue between the DOM and the editor's DOM-free parts. All changes go through commands and
// the history; a gesture (tools/) previews outside the history and is committed as one command.
import {rejectedOf, repeatByPitch, repeatSelection, splitCommand} from "./assist.js";
import {DeleteRects, duplicateRects, moveRects, setLabel} from "./commands.js";
import {mountFiles} from "./files.js";
import {identical} from "./geometry.js";
import {buildHelp} from "./help.js";
import {BOX_FIELDS, boxFields, setBoxCommand} from "./inspect.js";
import {ACTIONS, keyAction} from "./keys.js";
import {buildObjectList} from "./object-list.js";
import {freeView, layersNote, objectGroups, pickable, pickableSelection, toggleLayer} from "./objects.js";
import {buildPalette, markActive} from "./panel.js";
import {mountProposing} from "./proposing.js";
import {drawScene, grayPixels} from "./render.js";
import {download, makeApi} from "../common/server.js";
import {DraftKeeper, loadPhoto} from "./session.js";
import {mountPointer} from "./tools/pointer.js";
import {fitView, photoFilter, reveal} from "./tools/view.js";

const $ = (sel) => document.querySelector(sel);
const root = $("#editor");
const photoCode = root.dataset.photo;
const api = makeApi(document.querySelector("meta[name=csrf-token]").content);
const canvas = $("#canvas");
const ctx = canvas.getContext("2d");

const view = {scale: 1, ox: 0, oy: 0};  // screen = image * scale + offset
const ui = {tool: "draw", label: "window", selection: new Set(), drag: null, guides: [], proposals: [],
  proposalsFrom: "find similar", rejected: [], space: false, overlay: null, overlayAlpha: 0.5,
  layers: freeView(), openGroups: new Set()};  // layers: the classes hidden or locked in the object list
// the photo's API record and image, the segmentation and its history, the photo's gray levels once asked for,
// and the RectifyMode (rectify-mode.js) while the rectification step is open
let info = null, photo = null, seg = null, history = null, gray = null, rectifying = null;
const drafts = new DraftKeeper(api, photoCode, (text) => { $("#draft-note").textContent = text; });
const status = (text, kind = "") => Object.assign($("#status"), {textContent: text, className: `msg ${kind}`});

// --- loading and the state's echo in the page ----------------------------------------------------------------
async function load() {
  const forget = () => { root.dataset.segmentation = ""; };  // the saved version no longer fits the photo
  ({info, photo, seg, history} = await loadPhoto(api, photoCode, {status, forget}));
  history.onChange(changed);
  fit();
  buildPalette($("#palette"), pickLabel);
  pickLabel(ui.label);
  changed();
  if (sessionStorage.getItem("facaid-rectified") === photoCode) {
    sessionStorage.removeItem("facaid-rectified");
    status(`Rectified: this is the rectified photo, ${photo.naturalWidth}×${photo.naturalHeight} px. Draw its ` +
           "elements on it; Rectify again starts from the original.", "success");
  } else if (location.hash === "#rectify") await openRectify();  // the photo page's "Rectify it in the editor"
}

function changed() {
  for (const id of [...ui.selection]) if (!seg.rects.has(id)) ui.selection.delete(id);
  drafts.keep(seg, history);
  $("#undo").disabled = !history.canUndo;
  $("#redo").disabled = !history.canRedo;
  $("#dirty").textContent = history.dirty ? "unsaved changes" : "saved";
  const twice = identical([...seg.rects.values()]);
  const note = layersNote(ui.layers);
  $("#count").textContent = `${seg.size} rectangle${seg.size === 1 ? "" : "s"}, ${ui.selection.size} selected` +
    (note ? ` · ${note}` : "") +
    (twice.length ? " · " + twice.map((t) => `${t.count} identical ${t.label} rectangles`).join(", ") +
    " (delete the copies)" : "");
  $("#count").classList.toggle("warning", twice.length > 0);
  readout(null, null);
  objectList();
  selectionFields();
  draw();
}

// --- the selection's exact numbers (inspect.js) ----------------------------------------------------------------
function selectionFields() {
  const one = ui.selection.size === 1 ? seg.get([...ui.selection][0]) : null;
  const shown = one ? boxFields(one) : null;
  for (const k of BOX_FIELDS) Object.assign($(`#sel-${k}`), {disabled: !one, value: shown ? shown[k] : ""});
  $("#sel-apply").disabled = !one;
  $("#sel-size").textContent = one ? `${one.label} ${one.x1 - one.x0} × ${one.y1 - one.y0}` : "select one rectangle";
}

function applyBox() {
  if (ui.selection.size !== 1) return status("The numbers are those of one selected rectangle: select one.", "error");
  const typed = Object.fromEntries(BOX_FIELDS.map((k) => [k, $(`#sel-${k}`).value]));
  // a number field reports "" for what it cannot read ("1e", "--2"): say so rather than guess
  for (const k of BOX_FIELDS) if ($(`#sel-${k}`).validity.badInput) typed[k] = "(not a number)";
  const {command, error} = setBoxCommand(seg, [...ui.selection][0], typed);
  if (error) return status(`Not applied: ${error}`, "error");
  if (!command) return status("The rectangle already has these numbers.");
  run(command);
  status(`Set to ${BOX_FIELDS.map((k) => `${k} ${typed[k].trim()}`).join(", ")}.`, "success");
}

// --- the object list (objects.js): hide and lock are view state, no command -----------------------------------
function objectList() {
  buildObjectList($("#objects"), objectGroups(seg, ui.layers), ui.selection, ui.openGroups, {
    rebuild: objectList,
    toggle: (kind, label) => {
      ui.layers = toggleLayer(ui.layers, kind, label);
      ui.selection = pickableSelection(seg, ui.selection, ui.layers);
      changed();
    },
    select: (id) => {
      ui.selection = new Set([id]);
      Object.assign(view, reveal(view, seg.get(id), canvas.width, canvas.height));
      changed();
    },
  });
}

function run(cmd) {
  try {
    history.execute(cmd);
  } catch (err) {
    status(err.message, "error");
  }
}

// --- view ---------------------------------------------------------------------------------------------------------
/** The canvas fills the window below the rows above it (saving and the job stay in view there); the side panel
 * scrolls on its own beside it. Run again whenever those rows change height (a long message, the job showing). */
function layout() {
  const box = canvas.parentElement.getBoundingClientRect();
  const top = box.top + window.scrollY;  // the page's layout, whatever it is scrolled to
  const [w, h] = [Math.round(box.width), Math.max(400, Math.floor(window.innerHeight - top - 24))];
  if (canvas.width !== w || canvas.height !== h) [canvas.width, canvas.height] = [w, h];  // a resize clears it
  for (const panel of document.querySelectorAll(".editor-grid > aside")) panel.style.maxHeight = `${h}px`;
  draw();
}

function fit() {
  layout();
  if (seg) Object.assign(view, fitView(seg.width, seg.height, canvas.width, canvas.height));
  draw();
}

const toImage = (sx, sy) => [(sx - view.ox) / view.scale, (sy - view.oy) / view.scale];
const toScreen = (x, y) => [x * view.scale + view.ox, y * view.scale + view.oy];

function draw() {
  const scale = rectifying ? rectifying.scale : view.scale;  // the photo as the rectification step shows it
  $("#zoom").textContent = `zoom ${Math.round(100 * scale)} %`;
  if (rectifying) return rectifying.draw();
  if (seg) drawScene(ctx, {canvas, photo, seg, view, ui, fill: Number($("#fill").value)});
}

/** The photo's gray levels (`render.grayPixels`), made once it is first asked for; null without a photo. */
function photoGray() {
  if (photo && !gray) gray = grayPixels(photo, seg.width, seg.height);
  return gray;
}

/** The cursor's image position and the size of a single selected rectangle, in image pixels. */
function readout(x, y) {
  const one = ui.selection.size === 1 ? seg.get([...ui.selection][0]) : null;
  $("#cursor").textContent = (x === null ? "" : `x ${Math.round(x)}, y ${Math.round(y)}`) +
    (one ? ` · selection ${one.x1 - one.x0} × ${one.y1 - one.y0}` : "");
}

// --- palette and tools --------------------------------------------------------------------------------------------
function pickLabel(label) {
  ui.label = label;
  markActive("#palette button", "label", label);
  // with the select tool the class goes to the selection; with the draw tool it is the class of the next one
  if (ui.tool === "select" && ui.selection.size) run(setLabel([...ui.selection], label));
}

function setTool(tool) {
  ui.tool = tool;
  markActive("[data-tool]", "tool", tool);
  canvas.style.cursor = tool === "draw" ? "crosshair" : "default";
}

// --- the editor's parts (tools/pointer.js, proposing.js, files.js) share the state and its echo --------------------
const ed = {api, photoCode, root, canvas, ui, view, status, run, changed, draw, toImage, toScreen,
  get info() { return info; }, get photo() { return photo; }, get seg() { return seg; },
  get history() { return history; }, photoGray,
  get rectifying() { return rectifying; }, set rectifying(r) { rectifying = r; }};
const {similar, findCopies, completeNow, acceptProposals} = mountProposing(ed);
const {importJSON, saveNow, submitNow, openRectify, applyRectify} = mountFiles(ed);
mountPointer(ed, {readout, afterDrawn: () => { if ($("#auto-complete").checked) completeNow(); }});

// --- keyboard: keys.js maps keys to actions ------------------------------------------------------------------------
const keyHandlers = {undo: () => history.undo(), redo: () => history.redo(), duplicate, delete: () => removeSelected(),
  selectAll: () => {  // what can be picked: Ctrl+A then Delete must not remove a hidden or locked class
    ui.selection = new Set([...seg.rects.values()].filter((r) => pickable(ui.layers, r)).map((r) => r.id));
    changed();
  },
  fit,
  clear: () => { ui.selection.clear(); ui.rejected.push(...rejectedOf(ui.proposals)); ui.proposals = []; changed(); },
  tool: (a) => setTool(a.tool), label: (a) => pickLabel(a.label), accept: () => acceptProposals(),
  complete: () => completeNow(), similar: () => similar(), help: (a) => showHelp(a.open),
  applyBox: () => applyBox(),
  pan: () => { ui.space = true; canvas.style.cursor = "grab"; },
  nudge: (a) => run(moveRects(seg, [...ui.selection], a.dx, a.dy))};
const unhandled = ACTIONS.filter((name) => !keyHandlers[name]);
if (unhandled.length) throw new Error(`keys.js has actions the editor does not handle: ${unhandled.join(", ")}`);

window.addEventListener("keydown", (e) => {
  const field = e.target.closest("input, textarea, select");
  const a = keyAction(e, {selected: ui.selection.size, proposals: ui.proposals.length, help: !$("#help").hidden,
    field: field ? field.id : null, onButton: Boolean(e.target.closest("button, a"))});
  if (!a || (a.action === "complete" && e.repeat)) return;
  if (!["tool", "label", "clear"].includes(a.action)) e.preventDefault();
  keyHandlers[a.action](a);
});
window.addEventListener("keyup", (e) => { if (e.key === " ") { ui.space = false; setTool(ui.tool); } });
// A button clicked with the pointer does not take the focus: the keys go on to the canvas, so that Enter accepts
// proposals rather than pressing the last button clicked again (and leaves a field it was typed in).
root.addEventListener("mousedown", (e) => {
  if (!e.target.closest("button, label.button")) return;
  e.preventDefault();
  canvas.focus({preventScroll: true});
});

function showHelp(open) {
  $("#help").hidden = !open;
  if (open) $("#help-close").focus({preventScroll: true});  // Escape and Tab start in the dialog
  else canvas.focus({preventScroll: true});
}

// brightness and contrast: how the photo is shown, never the photo (nor an undo step)
function adjustPhoto() {
  const [brightness, contrast] = [Number($("#brightness").value), Number($("#contrast").value)];
  ui.photoFilter = photoFilter({brightness, contrast});
  $("#adjust-reset").disabled = ui.photoFilter === "none";
  $("#adjust-value").textContent = `${Math.round(100 * brightness)} %, ${Math.round(100 * contrast)} %`;
  draw();
}

const removeSelected = () => ui.selection.size && run(new DeleteRects([...ui.selection]));

function duplicate() {
  if (!ui.selection.size) return;
  const cmd = duplicateRects(seg, [...ui.selection], 10, 10);
  run(cmd);
  if (cmd.ids) ui.selection = new Set(cmd.ids);
  changed();
}

// --- repeat and find similar (assist.js) ---------------------------------------------------------------------------
function repeatSelected() {
  const n = (sel) => Number($(sel).value);
  carryOut(repeatSelection(seg, [...ui.selection], {cols: n("#rep-cols"), rows: n("#rep-rows"), gapX: n("#rep-gapx"),
    gapY: n("#rep-gapy")}));
}

/** Run a {command, message} | {error} plan of assist.js and say what happened; the pieces a split made, or the
 * copies, become the selection when `select`. */
function carryOut(plan, select = false) {
  if (plan.error) return status(plan.error, "error");
  run(plan.command);
  if (select && plan.command.ids?.length) ui.selection = new Set(plan.command.ids);
  status(plan.message, "success");
  changed();
}

// --- wiring ----------------------------------------------------------------------------------------------------------
for (const b of document.querySelectorAll("[data-tool]")) b.addEventListener("click", () => setTool(b.dataset.tool));
const on = (sel, event, fn) => $(sel).addEventListener(event, fn);
on("#undo", "click", () => history.undo());
on("#redo", "click", () => history.redo());
on("#delete", "click", removeSelected);
on("#duplicate", "click", duplicate);
on("#repeat", "click", repeatSelected);
on("#repeat-edge", "click", () => carryOut(repeatByPitch(seg, [...ui.selection], photoGray())));
on("#split", "click", () => carryOut(splitCommand(seg, [...ui.selection], {n: Number($("#split-n").value),
  direction: $("#split-dir").value, gap: Number($("#split-gap").value)}), true));
on("#similar", "click", similar);
on("#accept", "click", acceptProposals);
on("#complete", "click", completeNow);
on("#copies", "click", findCopies);
on("#fit", "click", fit);
on("#sel-apply", "click", applyBox);
on("#help-open", "click", () => showHelp(true));
on("#help-close", "click", () => showHelp(false));
on("#help", "click", (e) => { if (e.target.id === "help") showHelp(false); });  // a click beside the dialog
on("#export", "click", () => download(seg.toJSON(), `segmentation-${photoCode.slice(0, 8)}.json`));
on("#import", "change", (e) => {  // emptied after: the same file chosen again is read again
  const file = e.target.files[0];
  e.target.value = "";
  if (file) importJSON(file);
});
on("#save", "click", saveNow);
on("#submit", "click", submitNow);
on("#fill", "input", draw);
on("#brightness", "input", adjustPhoto);
on("#contrast", "input", adjustPhoto);
on("#adjust-reset", "click", () => { $("#brightness").value = $("#contrast").value = 1; adjustPhoto(); });
on("#overlay-alpha", "input", (e) => { ui.overlayAlpha = Number(e.target.value); draw(); });
on("#rectify", "click", openRectify);
on("#rectify-apply", "click", applyRectify);
on("#rectify-cancel", "click", () => { rectifying = null; $("#rectify-panel").hidden = true; draw(); });
window.addEventListener("resize", fit);
const rows = new ResizeObserver(layout);
for (const bar of document.querySelectorAll(".editor-bar")) rows.observe(bar);
window.addEventListener("beforeunload", (e) => { if (history?.dirty) { e.preventDefault(); e.returnValue = ""; } });
setTool("draw");
buildHelp($("#help-body"));
adjustPhoto();
load().catch((err) => status(`Could not load the photo: ${err.message}`, "error"));

// for tests and the console
window.facaidEditor = {get seg() { return seg; }, get history() { return history; },
  get rectifying() { return rectifying; },
  ui, view};
