// The side panel's controls built and marked: the class palette and which tool or class is active.
import {HOTKEYS, LABELS, cssColor} from "./labels.js";

/** One button per class, with its colour and hotkey, into `box`; `pick(label)` on a click. */
export function buildPalette(box, pick) {
  box.replaceChildren(...LABELS.map((label, i) => {
    const b = document.createElement("button");
    b.type = "button";
    b.dataset.label = label;
    b.append(swatch(label), ` ${label} `, Object.assign(document.createElement("kbd"), {textContent: HOTKEYS[i]}));
    b.addEventListener("click", () => pick(label));
    return b;
  }));
}

/** Mark as active the buttons matching `selector` whose `data-<key>` is `value`, and no other. */
export function markActive(selector, key, value) {
  for (const b of document.querySelectorAll(selector)) b.classList.toggle("active", b.dataset[key] === value);
}

// A label's colour swatch, its colour set as a style property: the site's Content-Security-Policy refuses style
// attributes written in markup.
export function swatch(label) {
  const span = Object.assign(document.createElement("span"), {className: "swatch"});
  span.style.background = cssColor(label);
  return span;
}
