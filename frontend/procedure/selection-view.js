// The procedure page's one selection as the page shows it (its DOM-free rules: selection.js): the nodes selected in
// the tree, the named parameters that stand for them, a line saying what is selected, and their rectangles outlined
// over the picture. A node in the tree, a parameter's name, a click on the picture and the 3D panel's pick select.
import {leafAt, leavesUnder, parametersOf, pictureToProcedure} from "./selection.js";

/** The selection of `page` ({proc, leaves, parameters}: the tree shown, where it draws each leaf, [label, x0, y0, x1,
 * y1, path], and its named parameters): `select(paths, by, name)`, `show()` and `keep()` for a new tree. */
export function mountSelection(page) {
  let selected = [];  // the node paths selected, what selected them, and the parameter when one did
  let selectedBy = null;
  let selectedName = null;

  // A new tree (a named edit, a variation loaded): a parameter's selection follows the parameter, any other ends, as
  // the paths may name other nodes now.
  function keep() {
    const p = selectedBy === "parameter" && page.parameters.find((q) => q.name === selectedName);
    if (p) selected = p.nodes;
    else { selected = []; selectedBy = selectedName = null; }
  }

  function select(paths, by, name = null) {
    selected = paths;
    selectedBy = by;
    selectedName = name;
    show();
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

  function show() {
    const one = selected.length === 1 ? selected[0] : null;
    for (const li of document.querySelectorAll("#tree li.selected")) li.classList.remove("selected");
    for (const path of selected) document.querySelector(`#tree li[data-path="${path}"]`)?.classList.add("selected");
    const named = one ? parametersOf(page.parameters, one) : [];
    for (const tr of document.querySelectorAll("#named tbody tr")) {
      tr.classList.toggle("selected", selectedBy === "parameter" ? tr.dataset.name === selectedName
        : named.includes(tr.dataset.name));
    }
    const drawn = leavesUnder(page.leaves, selected);
    const what = document.getElementById("selection-info");
    if (what) {
      const leaf = one && page.leaves.find((l) => l[5] === one);
      what.textContent = !selected.length ? "" : leaf ? `Selected: ${leaf[0]} · ${one}` + (named.length
        ? ` · ${named.map((n) => page.parameters.find((p) => p.name === n).label).join(", ")}` : "")
        : `Selected: ${selected.length === 1 ? one : `${selected.length} nodes`} · ${drawn.length} rectangles`;
    }
    drawOutlines(drawn, page.proc);
  }

  document.getElementById("render").addEventListener("click", (e) => {
    const img = e.currentTarget;
    const [x, y] = pictureToProcedure(e.offsetX, e.offsetY, img.clientWidth, img.clientHeight, page.proc.width,
      page.proc.height);
    const leaf = leafAt(page.leaves, x, y);
    select(leaf ? [leaf[5]] : [], "picture");
  });
  // the 3D panel's pick (preview3d.js): the same node, in the saved tree (the one the panel shows)
  document.addEventListener("facaid:select3d", (e) => select(e.detail.path ? [e.detail.path] : [], "3d"));

  return {select, show, keep};
}

function drawOutlines(drawn, proc) {
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
