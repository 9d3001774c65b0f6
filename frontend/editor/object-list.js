// The object list on the page: one group per class (its count, hide and lock) with an entry per rectangle that
// selects it. Built from objects.js's groups; the editor says what a click does.
import {swatch} from "./panel.js";

const button = (text, attrs = {}) => Object.assign(document.createElement("button"), {type: "button",
  textContent: text, ...attrs});

/** Fill `box` with the groups; `open` (a Set of labels) keeps the groups the user opened open across rebuilds.
 * `on`: {select(id), toggle(kind, label), rebuild()}. */
export function buildObjectList(box, groups, selection, open, on) {
  box.replaceChildren(...groups.map((g) => {
    const details = document.createElement("details");
    details.dataset.label = g.label;
    details.open = open.has(g.label);
    details.addEventListener("toggle", () => {
      if (details.open === open.has(g.label)) return;  // set while building
      if (details.open) open.add(g.label); else open.delete(g.label);
      on.rebuild();
    });
    const summary = document.createElement("summary");
    summary.append(swatch(g.label), " ");  // its colour set as a property: a style attribute breaks the page's CSP
    const name = Object.assign(document.createElement("span"), {className: "name", textContent: `${g.label} ${g.count}`});
    summary.append(name);
    for (const [kind, on1, off1] of [["hidden", "show", "hide"], ["locked", "unlock", "lock"]]) {
      const word = g[kind] ? on1 : off1;
      const b = button(word, {className: `layer ${kind}`, title: `${word} every ${g.label}`});
      b.setAttribute("aria-pressed", String(g[kind]));
      b.addEventListener("click", (e) => { e.preventDefault(); on.toggle(kind, g.label); });  // not the <details>
      summary.append(b);
    }
    const list = document.createElement("ol");
    if (details.open) {  // the entries of closed groups are not built: a facade can hold hundreds
      for (const r of g.rects) {
        const item = button(`${r.x0}, ${r.y0} · ${r.x1 - r.x0} × ${r.y1 - r.y0}`, {disabled: g.hidden || g.locked,
          className: selection.has(r.id) ? "active" : ""});
        item.dataset.id = r.id;
        item.addEventListener("click", () => on.select(r.id));
        const li = document.createElement("li");
        li.append(item);
        list.append(li);
      }
    }
    details.append(summary, list);
    return details;
  }));
}
