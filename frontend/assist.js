// Helpers that draw for the user, DOM-free: a grid of copies of one rectangle, proposals of look-alikes found in the
// photo (`match.js`), and the command that adds the proposals the user kept.
import {AddRects, repeatRects} from "./commands.js";
import {findSimilar} from "./match.js";

/** Copies of rectangle `id` in `cols` x `rows` with the given gaps (image pixels) between them. */
export function repeatCommand(seg, id, {cols, rows, gapX, gapY}) {
  const r = seg.get(id);
  return repeatRects(seg, id, {cols, rows, dx: r.x1 - r.x0 + gapX, dy: r.y1 - r.y0 + gapY});
}

/** What "Repeat" does with the selection `ids` ({cols, rows, gapX, gapY} as typed): {command, message} when one
 * rectangle is selected and some copy fits in the image, else {error}; both messages name what was there. */
export function repeatSelection(seg, ids, options) {
  if (ids.length !== 1) {
    return {error: ids.length ? `Repeat copies one rectangle, and ${ids.length} are selected: select one of them.`
      : "Repeat copies the selected rectangle: select one first."};
  }
  const {cols, rows, gapX, gapY} = options;
  if (!Number.isFinite(gapX) || !Number.isFinite(gapY)) return {error: "The gaps must be numbers (image pixels)."};
  let command;
  try {
    command = repeatCommand(seg, ids[0], options);
  } catch (err) {
    return {error: `Not repeated: ${err.message}.`};
  }
  const wanted = cols * rows - 1, made = command.records.length, {label} = seg.get(ids[0]);
  if (!made) return {error: wanted ? "Not repeated: no copy would lie inside the image." : "Not repeated: 1 × 1 is the rectangle itself."};
  const left = wanted > made ? `; ${wanted - made} outside the image left out` : "";
  return {command, message: `Added ${made} ${label} ${made === 1 ? "copy" : "copies"} (${cols} × ${rows})${left}.`};
}

/** Places in the photo (`gray`, `match.toGray`) that look like rectangle `id`, as proposals of its class; the
 * rectangles of that class already drawn are not proposed again. */
export function similarProposals(gray, seg, id, threshold) {
  const r = seg.get(id);
  const same = [...seg.rects.values()].filter((o) => o.label === r.label && o.id !== r.id);
  return findSimilar(gray, r, {threshold, exclude: same}).map((p) => ({...p, label: r.label}));
}

/** The proposal at image point (x, y), or undefined. */
export const proposalAt = (proposals, x, y) => proposals.find((p) => x >= p.x0 && x < p.x1 && y >= p.y0 && y < p.y1);

/** The command adding the proposals not rejected (`accepted === false`), or null when none is left. */
export function acceptCommand(proposals, name = "find similar") {
  const keep = proposals.filter((p) => p.accepted !== false);
  return keep.length ? new AddRects(keep.map(({label, x0, y0, x1, y1}) => ({label, x0, y0, x1, y1})), name) : null;
}

/** The proposals the user rejected (clicked away), as rectangles to pass back to completion so that it does not
 * propose them again. */
export function rejectedOf(proposals) {
  return proposals.filter((p) => p.accepted === false).map(({label, x0, y0, x1, y1}) => ({label, x0, y0, x1, y1}));
}
