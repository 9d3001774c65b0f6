// The object list's model, and what hiding and locking a class mean for drawing and picking. Hidden classes are
// not drawn and not hit; locked ones are drawn but cannot be selected, moved or resized. Both are view state:
// never a command, never in the segmentation that is saved. No DOM.
import {LABELS} from "./labels.js";

/** {hidden: Set of labels, locked: Set of labels}, both empty: everything shown and free. */
export const freeView = () => ({hidden: new Set(), locked: new Set()});

export const shown = (layers, r) => !layers?.hidden.has(r.label);
export const pickable = (layers, r) => !layers?.hidden.has(r.label) && !layers?.locked.has(r.label);

/** The rectangles grouped by class in the palette's order, classes with none left out:
 * [{label, count, hidden, locked, rects: [{id, label, x0, y0, x1, y1}] in drawing order}]. */
export function objectGroups(seg, layers) {
  const by = new Map();
  for (const r of seg.rects.values()) {
    if (!by.has(r.label)) by.set(r.label, []);
    by.get(r.label).push(r);
  }
  return LABELS.filter((label) => by.has(label)).map((label) => ({label, count: by.get(label).length,
    hidden: layers.hidden.has(label), locked: layers.locked.has(label), rects: by.get(label)}));
}

/** `layers` with `label` hidden or shown again (`kind` "hidden"), or locked or freed (`kind` "locked"). */
export function toggleLayer(layers, kind, label) {
  if (!LABELS.includes(label)) throw new Error(`unknown label ${JSON.stringify(label)}`);
  const next = {hidden: new Set(layers.hidden), locked: new Set(layers.locked)};
  if (next[kind].has(label)) next[kind].delete(label);
  else next[kind].add(label);
  return next;
}

/** The selection without what can no longer be picked (a class just hidden or locked): nudges, deletes and
 * relabels act on the selection, so it must hold nothing locked. */
export function pickableSelection(seg, selection, layers) {
  return new Set([...selection].filter((id) => seg.rects.has(id) && pickable(layers, seg.get(id))));
}

/** A line for the page: which classes are hidden and locked, or "" when none is. */
export function layersNote(layers) {
  const part = (name, set) => (set.size ? `${name}: ${LABELS.filter((l) => set.has(l)).join(", ")}` : "");
  return [part("hidden", layers.hidden), part("locked", layers.locked)].filter(Boolean).join("; ");
}

/** What a reconstruction of `seg` lacks when no facade rectangle is drawn: its procedure, pictures and 3D models hold
 * the elements alone, with no wall around them ("" when one is drawn). */
export function noFacadeNote(seg) {
  if ([...seg.rects.values()].some((r) => r.label === "facade")) return "";
  return "No facade is drawn: the procedure and its 3D models hold the elements alone, with no wall around them. " +
    "Draw the facade's outline (class facade) and reconstruct again to have it.";
}
