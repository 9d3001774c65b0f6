// The side panel's controls built and marked: the class palette and which tool or class is active.
import {HOTKEYS, LABELS, cssColor} from "./labels.js";

/** One button per class, with its colour and hotkey, into `box`; `pick(label)` on a click. */
export function buildPalette(box, pick) {
  box.replaceChildren(...LABELS.map((label, i) => {
    const b = document.createElement("button");
    b.type = "button";
    b.dataset.label = label;
    b.innerHTML = `<span class="swatch" style="background:${cssColor(label)}"></span> ${label} <kbd>${HOTKEYS[i]}</kbd>`;
    b.addEventListener("click", () => pick(label));
    return b;
  }));
}

/** Mark as active the buttons matching `selector` whose `data-<key>` is `value`, and no other. */
export function markActive(selector, key, value) {
  for (const b of document.querySelectorAll(selector)) b.classList.toggle("active", b.dataset[key] === value);
}
