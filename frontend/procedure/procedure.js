// The procedure page: an editable tree of parameters with live re-rendering, saved as a new version or as a new
// procedure, the history (history.js), variations (variations.js), the named parameters (named.js), the page's
// other forms (forms.js), and one selection shared by the picture, the named parameters, the tree and the 3D panel
// (selection-view.js): a click on an element of the picture selects its node in the tree and the parameters that
// stand for it; a click on a parameter's name or a node's outlines what it stands for in the picture. This module
// holds the tree shown and glues them.
import {mountForms} from "./forms.js";
import {accuracyText, mountHistory} from "./history.js";
import {drawNamed} from "./named.js";
import {Throttled, firstMessage, pageRequests} from "./requests.js";
import {mountSelection} from "./selection-view.js";
import {treeElement} from "./tree.js";
import {drawRanges, mountVariations} from "./variations.js";

const script = document.currentScript || document.querySelector("script[data-code]");
const code = script.dataset.code;
const csrf = document.querySelector("meta[name=csrf-token]").content;
const versions = mountHistory({code, owner: script.dataset.owner === "1", csrf});
const {send, renderPatiently} = pageRequests(csrf);
// the tree shown, where it draws each leaf: [label, x0, y0, x1, y1, path] (askNamed's answer), its named parameters
const page = {proc: JSON.parse(document.getElementById("procedure-data").textContent), leaves: [], parameters: []};
let renderTimer = null;
let renderedUrl = null;
const selection = mountSelection(page);

function drawTree() {
  document.getElementById("tree").replaceChildren(treeElement(page.proc.root, {
    edited: () => { namedStale = true; scheduleRender(); }, select: (path) => selection.select([path], "tree")}));
  selection.show();
}

// The named parameters of the tree shown (edited or not), read or set by the server, which edits the tree so that
// the rest keeps its size; each answer holds the parameters of the tree it returns.
let namedRequest = 0;
let namedStale = false;  // the tree was edited by hand: the named values are read again once it renders
async function askNamed(values = {}) {
  const status = document.getElementById("named-status");
  const mine = ++namedRequest;
  const [r, answer] = await send(`/api/v1/procedures/${code}/parameters`, "POST", {data: page.proc, values});
  if (mine !== namedRequest) return;  // a later edit asked again
  if (!r.ok) {
    status.textContent = `not set: ${answer.values || firstMessage(answer) || JSON.stringify(answer)}`;
    return;
  }
  status.textContent = "";
  page.leaves = answer.leaves || [];
  page.parameters = answer.parameters;
  if (Object.keys(values).length) {
    page.proc = answer.data;
    selection.keep();
    drawTree();
    scheduleRender();
  }
  drawRanges(answer.parameters);
  drawNamed(answer.parameters, {select: selection.select, ask: askNamed});
  selection.show();
}

function scheduleRender() {
  clearTimeout(renderTimer);
  renderTimer = setTimeout(async () => {
    try {
      const url = await renderPatiently(page.proc);
      if (renderedUrl) URL.revokeObjectURL(renderedUrl);
      renderedUrl = url;
      document.getElementById("render").src = url;
      showWhole();
      const overlay = document.getElementById("overlay");
      if (overlay) overlay.src = url;
      fitOverlay();
      const saved = document.getElementById("saved");
      if (saved) saved.textContent = "unsaved changes";
      if (namedStale) { namedStale = false; askNamed(); }
    } catch (err) {
      const saved = document.getElementById("saved");
      if (saved) saved.textContent = err instanceof Throttled ? err.message : `not valid: ${err.message}`;
      if (err instanceof Throttled) scheduleRender();  // the latest edit, once the server has room
    }
  }, 300);
}

// The figures shown are the saved version's, as the server measured them: never the ones of the tree before.
function showSaved(body) {
  const version = document.getElementById("version");
  if (version) version.textContent = body.version;
  const figure = document.getElementById("figure");
  figure.replaceChildren();
  if (body.accuracy !== null) {
    const b = document.createElement("b");
    b.textContent = accuracyText(body.accuracy);
    figure.append(" · pixel accuracy ", b);
  } else if (body.metrics?.unmeasured) {
    figure.append(` · pixel accuracy not measured: ${body.metrics.unmeasured}`);
  }
}

document.getElementById("save")?.addEventListener("click", async () => {
  const [r, body] = await send(`/api/v1/procedures/${code}/`, "PATCH", {data: page.proc});
  document.getElementById("saved").textContent = r.ok ? `saved as version ${body.version}`
    : `not saved: ${JSON.stringify(body)}`;
  if (r.ok) { showSaved(body); versions.refresh(); }
});

// A tree (the edited one, or a variation) as a procedure of the user's whose parent is this one; its page opens.
async function saveAsNew(data) {
  const [r, body] = await send(`/api/v1/procedures/${code}/save-as-new`, "POST", {data});
  if (r.ok) location.assign(`/procedures/${body.code}`);
  else document.getElementById("saved").textContent = `not saved: ${JSON.stringify(body)}`;
}
document.getElementById("save-new")?.addEventListener("click", () => saveAsNew(page.proc));

mountForms();
mountVariations({code, page, send, render: renderPatiently, owner: script.dataset.owner === "1",
  user: script.dataset.user === "1", saveAsNew, ask: askNamed, load: (v) => {
    page.proc = v;
    page.leaves = [];  // until the server says where the variant draws them
    selection.keep();
    drawTree();
    scheduleRender();
  }});

// The overlay lays the procedure over its photo only while the two have one size: a tree resized by an edit (a
// floor more) would be stretched over the photo, so it is hidden, and the note says why.
function fitOverlay() {
  const box = document.getElementById("overlay-box");
  if (!box) return;
  const [w, h] = [Math.round(page.proc.width), Math.round(page.proc.height)];
  const [pw, ph] = [Number(box.dataset.photoWidth), Number(box.dataset.photoHeight)];
  const fits = w === pw && h === ph;
  document.getElementById("overlay").hidden = !fits;
  const note = document.getElementById("overlay-note");
  note.hidden = fits;
  note.textContent = fits ? "" : `This procedure is ${w}×${h} px and its photo ${pw}×${ph}: the overlay shows a ` +
    "procedure of the photo's size, so it is hidden (an edit of the parameters resized it).";
}

drawTree();
fitOverlay();
/** The picture's width over its height, for the stylesheet to keep it (and the overlay) whole in the window. */
function showWhole() {
  const ratio = page.proc.width / Math.max(1, page.proc.height);
  document.getElementById("edit-cols").style.setProperty("--ratio", String(ratio));
}

showWhole();
if (document.getElementById("render").hasAttribute("src")) askNamed();  // a tree that cannot be drawn: said above
else document.getElementById("named-status").textContent = "The named parameters are not read: see above.";
versions.refresh().then(() => {
  // a re-run that fits worse is shown beside the version it continued
  const warned = document.querySelector("#rerun-warning [data-compare]");
  if (warned) versions.compare(...warned.dataset.compare.split(",").map(Number));
});
