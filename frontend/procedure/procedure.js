// The procedure page: an editable tree of parameters with live re-rendering, saved as a new version or as a new
// procedure, the history (history.js), variations, overlay opacity, and one selection shared by the
// picture, the named parameters, the tree and the 3D panel (selection.js): a click on an element of the picture
// selects its node in the tree and the parameters that stand for it; a click on a parameter's name or a node's
// outlines what it stands for in the picture.
import {accuracyText, mountHistory} from "./history.js";
import {drawRanges, rangesAsked, variantCaption} from "./variations.js";
import {treeElement} from "./tree.js";
import {leafAt, leavesUnder, parametersOf, pictureToProcedure} from "./selection.js";
import {busy, patientFetch} from "../common/server.js";

const script = document.currentScript || document.querySelector("script[data-code]");
const code = script.dataset.code;
const csrf = document.querySelector("meta[name=csrf-token]").content;
const versions = mountHistory({code, owner: script.dataset.owner === "1", csrf});
let proc = JSON.parse(document.getElementById("procedure-data").textContent);
let renderTimer = null;
let renderedUrl = null;
let leaves = [];  // where the shown tree draws each leaf: [label, x0, y0, x1, y1, path] (askNamed's answer)
let parameters = [];
let selected = [];  // the node paths selected, what selected them, and the parameter when one did
let selectedBy = null;
let selectedName = null;

function drawTree() {
  document.getElementById("tree").replaceChildren(treeElement(proc.root, {
    edited: () => { namedStale = true; scheduleRender(); }, select: (path) => select([path], "tree")}));
  showSelection();
}

// ---- the selection -------------------------------------------------------------------------------------------
// A new tree (a named edit, a variation loaded): a parameter's selection follows the parameter, any other ends, as
// the paths may name other nodes now.
function keepSelection() {
  const p = selectedBy === "parameter" && parameters.find((q) => q.name === selectedName);
  if (p) selected = p.nodes;
  else { selected = []; selectedBy = selectedName = null; }
}

function select(paths, by, name = null) {
  selected = paths;
  selectedBy = by;
  selectedName = name;
  showSelection();
  if (by === "picture" || by === "3d") {  // the node in the tree, scrolled to within the tree (the page stays)
    const li = document.querySelector(`#tree li[data-path="${paths[0]}"]`);
    if (li) {
      // the tree opens above the 3D panel: the page scrolls by what it grew, so the panel stays under the pointer
      const anchor = document.getElementById(by === "3d" ? "preview3d" : "picture-panel"), before = anchor
        .getBoundingClientRect().top;
      document.getElementById("advanced").open = true;
      window.scrollBy(0, anchor.getBoundingClientRect().top - before);
      const box = document.getElementById("tree");
      box.scrollTop += li.getBoundingClientRect().top - box.getBoundingClientRect().top - box.clientHeight / 3;
    }
  }
}

function showSelection() {
  const one = selected.length === 1 ? selected[0] : null;
  for (const li of document.querySelectorAll("#tree li.selected")) li.classList.remove("selected");
  for (const path of selected) document.querySelector(`#tree li[data-path="${path}"]`)?.classList.add("selected");
  const named = one ? parametersOf(parameters, one) : [];
  for (const tr of document.querySelectorAll("#named tbody tr")) {
    tr.classList.toggle("selected", selectedBy === "parameter" ? tr.dataset.name === selectedName
      : named.includes(tr.dataset.name));
  }
  const drawn = leavesUnder(leaves, selected);
  const what = document.getElementById("selection-info");
  if (what) {
    const leaf = one && leaves.find((l) => l[5] === one);
    what.textContent = !selected.length ? "" : leaf ? `Selected: ${leaf[0]} · ${one}` + (named.length
      ? ` · ${named.map((n) => parameters.find((p) => p.name === n).label).join(", ")}` : "")
      : `Selected: ${selected.length === 1 ? one : `${selected.length} nodes`} · ${drawn.length} rectangles`;
  }
  drawOutlines(drawn);
}

function drawOutlines(drawn) {
  const canvas = document.getElementById("selection");
  if (!canvas) return;
  const img = document.getElementById("render");  // over the picture itself, inside its border
  Object.assign(canvas.style, {left: `${img.offsetLeft + img.clientLeft}px`, top: `${img.offsetTop + img.clientTop}px`,
    width: `${img.clientWidth}px`, height: `${img.clientHeight}px`});
  canvas.width = Math.max(1, Math.round(proc.width));
  canvas.height = Math.max(1, Math.round(proc.height));
  const ctx = canvas.getContext("2d");
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  const line = Math.max(1, canvas.width / Math.max(1, canvas.clientWidth) * 2);  // 2 px as shown
  ctx.lineWidth = line;
  ctx.fillStyle = "rgba(255, 230, 0, 0.35)";
  ctx.strokeStyle = "#111";
  for (const [, x0, y0, x1, y1] of drawn) {
    ctx.fillRect(x0, y0, x1 - x0, y1 - y0);
    ctx.strokeRect(x0 + line / 2, y0 + line / 2, x1 - x0 - line, y1 - y0 - line);
  }
  canvas.dataset.outlined = String(drawn.length);  // for the page's tests
}

document.getElementById("render").addEventListener("click", (e) => {
  const img = e.currentTarget;
  const [x, y] = pictureToProcedure(e.offsetX, e.offsetY, img.clientWidth, img.clientHeight, proc.width, proc.height);
  const leaf = leafAt(leaves, x, y);
  select(leaf ? [leaf[5]] : [], "picture");
});
// the 3D panel's pick (preview3d.js): the same node, in the saved tree (the one the panel shows)
document.addEventListener("facaid:select3d", (e) => select(e.detail.path ? [e.detail.path] : [], "3d"));

// The named parameters of the tree shown (edited or not), read or set by the server, which edits the tree so that
// the rest keeps its size; each answer holds the parameters of the tree it returns.
let namedRequest = 0;
let namedStale = false;  // the tree was edited by hand: the named values are read again once it renders
async function askNamed(values = {}) {
  const status = document.getElementById("named-status");
  const mine = ++namedRequest;
  const [r, answer] = await send(`/api/v1/procedures/${code}/parameters`, "POST", {data: proc, values});
  if (mine !== namedRequest) return;  // a later edit asked again
  if (!r.ok) {
    status.textContent = `not set: ${answer.values || firstMessage(answer) || JSON.stringify(answer)}`;
    return;
  }
  status.textContent = "";
  leaves = answer.leaves || [];
  parameters = answer.parameters;
  if (Object.keys(values).length) {
    proc = answer.data;
    keepSelection();
    drawTree();
    scheduleRender();
  }
  drawNamed(answer.parameters);
  showSelection();
}

// The first message of an error answer ({"detail": ...}, {"data": {"data": ...}}, {"values": [...]}), for a person
function firstMessage(answer) {
  if (typeof answer === "string") return answer;
  for (const value of Object.values(answer && typeof answer === "object" ? answer : {})) {
    const text = firstMessage(Array.isArray(value) ? value[0] : value);
    if (text) return text;
  }
  return "";
}

function drawNamed(parameters) {
  drawRanges(parameters);
  document.querySelector("#named tbody").replaceChildren(...parameters.map((p) => {
    const tr = document.createElement("tr");
    tr.dataset.name = p.name;
    tr.dataset.nodes = p.nodes.join(" ");
    const th = document.createElement("th");
    th.textContent = p.label;
    th.title = "select: what it stands for is outlined in the picture";
    th.addEventListener("click", () => select(p.nodes, "parameter", p.name));
    const input = document.createElement("input");
    input.type = "number"; input.name = p.name; input.min = p.min; input.max = p.max;
    input.step = p.integer ? 1 : 0.5; input.value = p.integer ? String(p.value) : p.value.toFixed(1);
    if (p.min === p.max) { input.disabled = true; input.title = "no repeat lays them out: edit the tree"; }
    input.addEventListener("change", () => {
      const v = Number(input.value);
      if (input.value !== "" && Number.isFinite(v)) askNamed({[p.name]: v});
    });
    const unit = document.createElement("td");
    unit.className = "meta"; unit.textContent = p.unit === "px" ? "px" : "";
    const td = document.createElement("td");
    td.append(input);
    tr.append(th, td, unit, checkNote(p));
    return tr;
  }));
}

// Beside a count, in words, what the server's check of its edits found (checked false: an edit of it is not clean,
// as a person would see it; null: not checked, and why); a length is not judged, and says nothing.
function checkNote(p) {
  const note = document.createElement("td");
  note.className = "check-note";
  if (p.checked === false) {
    note.classList.add("failed");
    note.textContent = (p.edits || []).filter((e) => !e.clean).map((e) => e.said).join("; ") || p.check;
  } else if (p.checked === null && p.unit === "count" && p.check) {
    note.classList.add("meta");
    note.textContent = p.check;
  }
  if (p.check && p.unit === "count") note.title = p.check;  // both edits' words
  return note;
}

class Throttled extends Error {
  constructor(seconds) { super(`busy: trying again in ${seconds} s`); this.seconds = seconds; }
}

async function render(data) {
  const r = await fetch("/api/v1/render", {method: "POST", credentials: "same-origin",
    headers: {"Content-Type": "application/json", "X-CSRFToken": csrf}, body: JSON.stringify(data)});
  if (busy(r)) {  // throttled, or every heavy slot of the process taken
    throw new Throttled(Math.max(1, Number(r.headers.get("Retry-After")) || 1));
  }
  if (!r.ok) { const e = await r.json().catch(() => ({})); throw new Error(JSON.stringify(e)); }
  return URL.createObjectURL(await r.blob());
}

// rendering is rate-limited per account (the server's "heavy" rate) and capped per process (a 503 when busy): wait
// as told and try once more
async function renderPatiently(data) {
  try {
    return await render(data);
  } catch (err) {
    if (!(err instanceof Throttled)) throw err;
    await new Promise((done) => setTimeout(done, err.seconds * 1000));
    return render(data);
  }
}

function scheduleRender() {
  clearTimeout(renderTimer);
  renderTimer = setTimeout(async () => {
    try {
      const url = await renderPatiently(proc);
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

async function send(url, method, data) {
  const r = await patientFetch(url, {method, credentials: "same-origin",
    headers: {"Content-Type": "application/json", "X-CSRFToken": csrf}, body: JSON.stringify(data)});
  return [r, await r.json().catch(() => ({}))];
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
  const [r, body] = await send(`/api/v1/procedures/${code}/`, "PATCH", {data: proc});
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
document.getElementById("save-new")?.addEventListener("click", () => saveAsNew(proc));

// The CGA rules and the 3D models (the links marked data-scaled) are in metres: a facade width the user knows sets
// their scale (metres per pixel of the saved procedure); left empty, the server's default (the page says which).
const widthField = document.getElementById("width-m");
// the server's bound
if (widthField) widthField.max = Number(widthField.dataset.maxScale) * Number(widthField.dataset.px);
widthField?.addEventListener("input", () => {
  const metres = Number(widthField.value);
  const scaled = widthField.value !== "" && Number.isFinite(metres) && metres > 0 && metres <= Number(widthField.max);
  widthField.setCustomValidity(widthField.value === "" || scaled ? "" : `a width from 0.1 to ${widthField.max} m`);
  widthField.reportValidity();
  for (const link of document.querySelectorAll("a[data-scaled]")) {
    const base = link.getAttribute("href").split("?")[0];
    link.setAttribute("href", scaled ? `${base}?metres_per_pixel=${metres / Number(widthField.dataset.px)}` : base);
  }
});

// a form that asks first (delete): its handler is here, as the site's Content-Security-Policy refuses inline ones
for (const form of document.querySelectorAll("form[data-confirm]")) {
  form.addEventListener("submit", (e) => { if (!confirm(form.dataset.confirm)) e.preventDefault(); });
}
document.getElementById("opacity")?.addEventListener("input", (e) => {
  document.getElementById("overlay").style.opacity = e.target.value;
});

document.getElementById("vary").addEventListener("click", async () => {
  const seed = Number(document.getElementById("seed").value) || 0;
  const status = document.getElementById("vary-status");
  const ranges = rangesAsked();
  if (typeof ranges === "string") { status.textContent = ranges; return; }
  const body = {n: 8, seed};
  if (Object.keys(ranges).length) body.ranges = ranges;
  if (document.getElementById("include-unchecked")?.checked) body.include_unchecked = true;
  const [r, answer] = await send(`/api/v1/procedures/${code}/variations`, "POST", body);
  const grid = document.getElementById("variants");
  if (!r.ok) {
    status.textContent = `no variations: ${answer.ranges || answer.data || answer.detail || JSON.stringify(answer)}`;
    document.getElementById("vary-left-out").hidden = true;
    return;
  }
  status.textContent = "";
  // what was not varied, and why: the counts whose edits are not clean (unless asked for)
  const leftOut = document.getElementById("vary-left-out");
  leftOut.hidden = !(answer.left_out || []).length;
  leftOut.textContent = leftOut.hidden ? "" : "Left out: " + answer.left_out.map((o) =>
    `${parameters.find((q) => q.name === o.name)?.label || o.name} (${o.reason})`).join("; ") +
    ". Tick \"vary those too\" to vary them anyway.";
  const {variants} = answer;
  grid.replaceChildren();
  for (const v of variants) {
    const card = document.createElement("div");
    card.className = "card";
    const img = document.createElement("img");
    img.src = await renderPatiently(v);
    img.alt = v.meta?.variation || "variant";
    const caption = document.createElement("div");
    caption.className = "meta";
    const drawn = Object.entries(v.meta?.parameters || {}).map(([name, value]) => {
      const p = parameters.find((q) => q.name === name);
      return `${p?.label || name} ${value}${p?.unit === "px" ? " px" : ""}`;
    }).join(", ");
    caption.textContent = variantCaption(v, drawn);
    const use = document.createElement("button");
    use.textContent = "Edit this one";
    use.title = "load it into the parameters: saving it then makes a new version, or a new procedure";
    use.addEventListener("click", () => {
      proc = v;
      leaves = [];  // until the server says where the variant draws them
      keepSelection();
      drawTree();
      scheduleRender();
      // the variant is now the picture and the parameters above: shown there, and said
      document.getElementById("render").scrollIntoView({behavior: "smooth", block: "start"});
      const keep = script.dataset.owner === "1" ? "save it as a new version, or as a new procedure (Advanced)"
        : script.dataset.user === "1" ? "save it as a procedure of your own (Advanced)" : "log in to keep it";
      askNamed().then(() => {
        document.getElementById("named-status").textContent = `Loaded the variant ${caption.textContent}: ` +
          `change it, then ${keep}.`;
      });
    });
    card.append(img, caption, use);
    if (script.dataset.user === "1") {
      const keep = document.createElement("button");
      keep.textContent = "Save as new procedure";
      keep.addEventListener("click", () => saveAsNew(v));
      card.append(" ", keep);
    }
    grid.append(card);
  }
});

// The overlay lays the procedure over its photo only while the two have one size: a tree resized by an edit (a
// floor more) would be stretched over the photo, so it is hidden, and the note says why.
function fitOverlay() {
  const box = document.getElementById("overlay-box");
  if (!box) return;
  const [w, h] = [Math.round(proc.width), Math.round(proc.height)];
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
  document.getElementById("edit-cols").style.setProperty("--ratio", String(proc.width / Math.max(1, proc.height)));
}

showWhole();
if (document.getElementById("render").hasAttribute("src")) askNamed();  // a tree that cannot be drawn: said above
else document.getElementById("named-status").textContent = "The named parameters are not read: see above.";
versions.refresh().then(() => {
  // a re-run that fits worse is shown beside the version it continued
  const warned = document.querySelector("#rerun-warning [data-compare]");
  if (warned) versions.compare(...warned.dataset.compare.split(",").map(Number));
});

// Sharing the procedure asks whether to share its photo too (the question shows while the choice is not private),
// and says what viewers will see once saved, for the choice made (sharing.previews).
const shareVisibility = document.querySelector("#visibility-form select[name=visibility]");
if (shareVisibility) {
  const sharePhoto = document.getElementById("share-photo");
  const willSee = document.getElementById("viewers-will-see");
  const previews = JSON.parse(document.getElementById("sharing-previews").textContent);
  const ask = () => {
    if (sharePhoto) sharePhoto.hidden = shareVisibility.value === "private";
    const photo = sharePhoto && !sharePhoto.hidden && sharePhoto.querySelector("input").checked;
    const changed = shareVisibility.value !== shareVisibility.dataset.saved || photo;
    willSee.hidden = !changed;
    willSee.textContent = changed ? `Once saved: ${previews[shareVisibility.value + (photo ? "+photo" : "")]}` : "";
  };
  shareVisibility.dataset.saved = shareVisibility.value;
  shareVisibility.addEventListener("change", ask);
  if (sharePhoto) sharePhoto.querySelector("input").addEventListener("change", ask);
  ask();
}
