// The shortcuts' help overlay, its rows built from keys.js's tables, so that it lists what the keys do.
import {POINTER, shortcutRows} from "./keys.js";

function table(title, rows) {
  const section = document.createElement("section");
  const h = Object.assign(document.createElement("h3"), {textContent: title});
  const t = document.createElement("table");
  for (const {keys, does} of rows) {
    const tr = t.insertRow();
    tr.insertCell().append(Object.assign(document.createElement("kbd"), {textContent: keys}));
    tr.insertCell().textContent = does;
  }
  section.append(h, t);
  return section;
}

/** Fill `box` with the keys' and the pointer's tables. */
export function buildHelp(box) {
  box.replaceChildren(table("Keys", shortcutRows()), table("Pointer", POINTER));
}
