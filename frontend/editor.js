// The editor page: the glue between the DOM and the editor's DOM-free parts. All changes go through commands and
// the history; a gesture (frontend/tools/) previews outside the history and is committed as one command.
import {acceptCommand, proposalAt, rejectedOf, repeatByPitch, repeatSelection, similarProposals, splitCommand}
  from "./assist.js";
import {AddRects, DeleteRects, ReplaceAll, duplicateRects, moveRects, setLabel} from "./commands.js";
import {identical} from "./geometry.js";
import {buildHelp} from "./help.js";
import {BOX_FIELDS, boxFields, setBoxCommand} from "./inspect.js";
import {ACTIONS, keyAction} from "./keys.js";
import {buildObjectList} from "./object-list.js";
import {freeView, layersNote, objectGroups, pickable, pickableSelection, toggleLayer} from "./objects.js";
import {buildPalette, markActive} from "./panel.js";
import {chipAt, chipMembers, chips, copyOf, toggleRejected, unitIndices} from "./proposals.js";
import {openRectifyMode} from "./rectify-mode.js";
import {drawScene, grayPixels} from "./render.js";
import {download, makeApi} from "./server.js";
import {DraftKeeper, loadPhoto, readSegmentationFile, rectify, save, submit} from "./session.js";
import {PinchGesture, clampScale, fitView, photoFilter, reveal} from "./tools/view.js";
import {press} from "./tools/select.js";

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
  $("#count").textContent = `${seg.size} rectangle${seg.size === 1 ? "" : "s"}, ${ui.selection.size} selected` + (note ? ` · ${note}` : "") +
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
const chipUnder = (e) => chipAt(chips(ui.proposals, toScreen), e.offsetX, e.offsetY);

function draw() {
  if (rectifying) return rectifying.draw();
  if (seg) drawScene(ctx, {canvas, photo, seg, view, ui, fill: Number($("#fill").value)});
  $("#zoom").textContent = `zoom ${Math.round(100 * view.scale)} %`;
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

// --- pointer: frontend/tools/ turns presses and moves into previews and commands ----------------------------------
const toolContext = () => ({seg, selection: ui.selection, label: ui.label, scale: view.scale, snap: $("#snap").checked,
  layers: ui.layers});
const pointers = new Map();  // pointerId -> [offsetX, offsetY] while down: two pinch

function pointerOf(e) {
  const [x, y] = toImage(e.offsetX, e.offsetY);
  return {x, y, sx: e.offsetX, sy: e.offsetY, shift: e.shiftKey, alt: e.altKey};
}

canvas.addEventListener("pointerdown", (e) => {
  canvas.setPointerCapture(e.pointerId);
  if (rectifying) return rectifying.pointerdown(e);
  pointers.set(e.pointerId, [e.offsetX, e.offsetY]);
  if (pointers.size > 2) return;
  if (pointers.size === 2) {  // a gesture started by the first finger is dropped
    ui.drag = new PinchGesture([...pointers.values()], view);
    ui.guides = [];
    return draw();
  }
  const pan = ui.space || e.button === 1;
  // a press on a proposal or a row's chip is the start of a click that rejects it (below): it selects and moves
  // nothing under it
  if (!pan && (chipUnder(e) || proposalAt(ui.proposals, ...toImage(e.offsetX, e.offsetY)))) return;
  const {gesture, selection} = press(ui.tool, pointerOf(e), toolContext(), view, {pan});
  ui.drag = gesture;
  ui.selection = selection;
  changed();
});

canvas.addEventListener("pointermove", (e) => {
  if (seg && !rectifying) readout(...toImage(e.offsetX, e.offsetY));
  if (rectifying) return rectifying.pointermove(e);
  if (pointers.has(e.pointerId)) pointers.set(e.pointerId, [e.offsetX, e.offsetY]);
  const d = ui.drag;
  if (!d) return;
  if (d.kind === "pinch") {
    if (pointers.size >= 2) Object.assign(view, d.view([...pointers.values()]));
    return draw();
  }
  const result = d.move(pointerOf(e), toolContext());
  ui.guides = result.guides;
  if (result.view) Object.assign(view, result.view);
  draw();
});

canvas.addEventListener("pointercancel", (e) => {  // the browser took the gesture: nothing is committed
  pointers.delete(e.pointerId);
  if (!rectifying) [ui.drag, ui.guides] = [null, []];
  draw();
});

canvas.addEventListener("pointerup", (e) => {
  pointers.delete(e.pointerId);
  if (rectifying) return rectifying.pointerup();
  const d = ui.drag;
  ui.drag = null;
  ui.guides = [];
  if (!d || d.kind === "pinch") return draw();
  const {command, selection, selectAdded} = d.up(toolContext());
  if (selection) ui.selection = selection;
  if (command) {
    run(command);
    if (selectAdded && command.ids) ui.selection = new Set(command.ids);
  }
  changed();
  if (d.kind === "draw" && command && $("#auto-complete").checked) completeNow();  // proposals after each drawn one
});

canvas.addEventListener("wheel", (e) => {
  e.preventDefault();
  const [x, y] = toImage(e.offsetX, e.offsetY);
  view.scale = clampScale(view.scale * Math.exp(-e.deltaY * 0.0015));
  view.ox = e.offsetX - x * view.scale;
  view.oy = e.offsetY - y * view.scale;
  draw();
}, {passive: false});

// proposals: a click rejects (or takes back) one, with the rest of its copy, before any tool sees the press;
// Shift+click accepts it alone; a row's or column's chip does the same for all of the row or column
canvas.addEventListener("click", (e) => {
  if (ui.drag) return;
  const chip = chipUnder(e);
  const p = chip ? null : proposalAt(ui.proposals, ...toImage(e.offsetX, e.offsetY));
  const members = chip ? chipMembers(ui.proposals, chip) : p ? copyOf(ui.proposals, p) : [];
  if (!members.length) return;
  if (e.shiftKey) {  // a row or column adds what is not rejected in it; one proposal is added as it is
    const taken = chip ? members.filter((q) => q.accepted !== false) : members;
    ui.proposals = ui.proposals.filter((q) => !taken.includes(q));
    const what = chip ? `a ${chip.kind} of ${taken.length}` : `one ${p.label}`;
    if (taken.length) run(acceptCommand(taken.map((q) => ({...q, accepted: true})), `accept ${what}`));
    changed();
  } else {
    const rejected = toggleRejected(members);
    if (chip) status(`${rejected ? "Rejected" : "Took back"} a ${chip.kind} of ${members.length} proposals.`);
    draw();
  }
}, true);

// --- keyboard: frontend/keys.js maps keys to actions ---------------------------------------------------------------
const keyHandlers = {undo: () => history.undo(), redo: () => history.redo(), duplicate, delete: () => removeSelected(),
  selectAll: () => {  // what can be picked: Ctrl+A then Delete must not remove a hidden or locked class
    ui.selection = new Set([...seg.rects.values()].filter((r) => pickable(ui.layers, r)).map((r) => r.id));
    changed();
  },
  fit, clear: () => { ui.selection.clear(); ui.rejected.push(...rejectedOf(ui.proposals)); ui.proposals = []; changed(); },
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

// --- repeat and find similar (frontend/assist.js) ------------------------------------------------------------------
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

// run again by Enter in the threshold field (keys.js), with the new threshold; the old proposals go
function similar() {
  // with no single selection, while its proposals are shown, the search runs again for the rectangle it ran for
  const again = ui.proposalsFrom === "find similar" && ui.proposals.length && seg.rects.has(ui.similarSource);
  if (ui.selection.size !== 1 && !again) {
    return status(`Find similar looks for copies of one rectangle, and ${ui.selection.size} are selected.`, "error");
  }
  const source = ui.selection.size === 1 ? [...ui.selection][0] : ui.similarSource;
  const field = $("#sim-threshold"), threshold = Number(field.value);
  if (!(field.value !== "" && threshold >= Number(field.min) && threshold <= Number(field.max))) {
    return status(`The threshold must be a number from ${field.min} to ${field.max}.`, "error");
  }
  gray = gray || grayPixels(photo, seg.width, seg.height);
  ui.proposals = similarProposals(gray, seg, source, threshold);
  [ui.proposalsFrom, ui.similarSource] = ["find similar", source];
  status(ui.proposals.length ? `${ui.proposals.length} proposals at threshold ${threshold}: click one to reject it; ` +
    '"Accept" or Enter adds the rest (Enter in the threshold field searches again).'
    : `No similar places found at threshold ${threshold}.`);
  draw();
}

// find copies (facaid.photo.copies on the server): where the selected unit, a window with what is drawn around it,
// repeats in the photo
async function findCopies() {
  if (!ui.selection.size) return status("Find copies looks for copies of the selected unit: select a window and " +
    "what belongs to it (sill, blind, hood) first.", "error");
  const drawn = seg.toJSON(), unit = unitIndices(seg, ui.selection);
  await propose({...drawn, unit}, drawn, "find copies", (n, copies) => n
    ? `${copies} copies of the unit (${n} proposals), scored by how alike they look: click one to reject its copy, ` +
      "a row's or column's chip to reject all of it (Shift: add it alone), Enter or \"Accept\" to add the rest."
    : `No copies of the unit found in the photo${rejectedNote()}.`);
}

// completion (facaid.complete on the server): the elements not drawn yet, from the rows and columns drawn so far
async function completeNow() {
  const drawn = seg.toJSON();
  await propose({...drawn}, drawn, "complete", (n) => n ? `${n} proposals: click one to ` +
    'reject it, Shift+click to add it alone, Enter or "Accept" to add the rest.'
    : `Nothing to propose yet: draw a few elements of a row and a column${rejectedNote()}.`);
}

// the places rejected before are never proposed again in this session: said where nothing comes back
const rejectedNote = () => ui.rejected.length
  ? ` (${ui.rejected.length} place${ui.rejected.length === 1 ? "" : "s"} you rejected before ` +
    `${ui.rejected.length === 1 ? "is" : "are"} not proposed again)` : "";

// one request for proposals at a time; those shown stay until the answer replaces them (the rejected ones are
// remembered and passed back), unless the drawing changed meanwhile
async function propose(body, drawn, from, message) {
  if (ui.completing) return;
  const known = new Set(ui.rejected.map((r) => JSON.stringify(r)));
  ui.rejected.push(...rejectedOf(ui.proposals).filter((r) => !known.has(JSON.stringify(r))));
  body.rejected = ui.rejected;
  ui.completing = true;
  try {
    const {proposals} = await api(`/api/v1/photos/${photoCode}/complete`, {method: "POST", body: JSON.stringify(body)});
    if (JSON.stringify(seg.toJSON()) !== JSON.stringify(drawn)) {
      return status(`The drawing changed meanwhile: ${from === "complete" ? "press C" : "ask"} again.`);
    }
    ui.proposals = proposals;
    ui.proposalsFrom = from;
    status(message(proposals.length, new Set(proposals.map((p) => p.copy)).size));
  } catch (err) {
    status(`No proposals: ${err.message}`, "error");
  } finally {
    ui.completing = false;
    draw();
  }
}

function acceptProposals() {
  ui.rejected.push(...rejectedOf(ui.proposals));
  const cmd = acceptCommand(ui.proposals, ui.proposalsFrom);
  ui.proposals = [];
  if (cmd) run(cmd);
  status(cmd ? `Added ${cmd.records.length} proposal${cmd.records.length === 1 ? "" : "s"}.` : "Nothing was added: " +
    "every proposal was rejected.", cmd ? "success" : "");
  changed();
}

// --- files, saving, submitting, rectifying (frontend/session.js) ------------------------------------------------
async function importJSON(file) {
  try {
    const original = info.rectified && info.corners ? {width: info.width, height: info.height, corners: info.corners}
      : null;  // an annotation of the photo as taken is carried through its rectification
    const {rects, warnings} = await readSegmentationFile(file, seg.width, seg.height, api, original);
    const choice = seg.size ? await askImport(seg.size, rects.length) : "replace";
    if (choice === "cancel") return status("Not imported: nothing changed.");
    run(choice === "merge" ? new AddRects(rects, "import") : new ReplaceAll(rects));
    status(`Imported ${rects.length} rectangles${choice === "merge" ? `, added to the ${seg.size - rects.length} ` +
      "drawn" : ""}.${warnings.map((w) => ` Note: ${w}.`).join("")}`, "success");
  } catch (err) {
    status(`Not imported: ${err.message}`, "error");
  }
}

// "replace", "merge" or "cancel": what to do with the rectangles drawn when a file brings others
function askImport(drawn, coming) {
  const dialog = $("#import-choice");
  $("#import-question").textContent = `${drawn} rectangles are drawn and the file has ${coming}: replace the drawn ` +
    "ones with the file's, or add the file's to them?";
  return new Promise((resolve) => {
    dialog.addEventListener("close", () => resolve(dialog.returnValue || "cancel"), {once: true});
    dialog.returnValue = "";
    dialog.showModal();
  });
}

async function saveNow() {
  try {
    status(`Saved as version ${(await save(api, photoCode, seg, history)).version}.`, "success");
  } catch (err) {
    status(`Not saved: ${err.message}`, "error");
  }
}

async function submitNow() {
  try {
    const k = Number($("#k").value);
    if (!Number.isInteger(k) || k < 1 || k > Number($("#k").max)) {
      return status(`Not submitted: K must be a whole number from 1 to ${$("#k").max}.`, "error");
    }
    const job = await submit(api, photoCode, seg, history, {saved: root.dataset.segmentation, k,
      onSaved: (code) => { root.dataset.segmentation = code; },
      progress: (j) => {
        $("#job").hidden = false;
        $("#job-status").textContent = `${j.status}${j.status === "running" && j.stage ? ` (${j.stage})` : ""}`;
        $("#job-progress").value = j.progress;
      }});
    if (job.status === "failed") return status(`The reconstruction failed: ${job.message}`, "error");
    ui.overlay = new Image();
    ui.overlay.src = `/api/v1/procedures/${job.result}/download/labels.png`;
    await ui.overlay.decode();
    $("#result-link").href = `/procedures/${job.result}`;
    $("#result").hidden = false;
    draw();
  } catch (err) {
    status(`Not submitted: ${err.message}`, "error");
  }
}

async function openRectify() {
  rectifying = await openRectifyMode(canvas, $("#rectify-preview"), info);
  $("#rectify-panel").hidden = false;
  $("#rectify-panel").scrollIntoView({block: "nearest"});  // its step in view in the side panel
  const side = info.real_height_m != null ? "height" : "width";
  $("#real-side").value = side;
  $("#real-metres").value = info[`real_${side}_m`] ?? "";
  status("Drag the four corners onto the facade's corners; the preview shows the result.");
}

/** The real size typed in the rectification panel, as the photo's fields ({real_width_m: 12.5}: the other side
 * cleared; both null when the field is empty); throws a message for what is not a size. */
function typedRealSize() {
  const input = $("#real-metres"), side = $("#real-side").value;
  const size = {real_width_m: null, real_height_m: null};
  if (input.value === "" && !input.validity.badInput) return size;
  const metres = Number(input.value);
  if (!Number.isFinite(metres) || metres < Number(input.min) || metres > Number(input.max)) {
    throw new Error(`the real ${side} must be a number of metres from ${input.min} to ${input.max}`);
  }
  return {...size, [`real_${side}_m`]: metres};
}

async function applyRectify() {
  if (seg.size && !confirm("Rectifying changes the image: the rectangles drawn so far do not carry over. Go on?")) return;
  try {
    const size = typedRealSize();
    if (size.real_width_m !== info.real_width_m || size.real_height_m !== info.real_height_m) {
      Object.assign(info, await api(`/api/v1/photos/${photoCode}/`, {method: "PATCH", body: JSON.stringify(size)}));
    }
    await rectify(api, photoCode, rectifying.corners);
    history.markSaved();
    // the editor anew on the rectified photo, saying so; without the #rectify that opened the step
    sessionStorage.setItem("facaid-rectified", photoCode);
    location.replace(location.pathname + location.search);
  } catch (err) {
    status(`Not rectified: ${err.message}`, "error");
  }
}

// --- wiring ----------------------------------------------------------------------------------------------------------
for (const b of document.querySelectorAll("[data-tool]")) b.addEventListener("click", () => setTool(b.dataset.tool));
const on = (sel, event, fn) => $(sel).addEventListener(event, fn);
on("#undo", "click", () => history.undo());
on("#redo", "click", () => history.redo());
on("#delete", "click", removeSelected);
on("#duplicate", "click", duplicate);
on("#repeat", "click", repeatSelected);
on("#repeat-edge", "click", () => carryOut(repeatByPitch(seg, [...ui.selection])));
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
window.facaidEditor = {get seg() { return seg; }, get history() { return history; }, get rectifying() { return rectifying; },
  ui, view};
