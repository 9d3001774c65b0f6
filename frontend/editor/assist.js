// Helpers that draw for the user, DOM-free: a grid of copies of one rectangle, copies at the pitch of two examples
// to the facade's edge, a rectangle split into columns or rows, proposals of look-alikes found in the photo
// (`match.js`), and the command that adds the proposals the user kept.
import {AddRects, Batch, DeleteRects, repeatRects} from "./commands.js";
import {contains, intersects, translate} from "./geometry.js";
import {findSimilar, matchNear} from "./match.js";

/** Copies of rectangle `id` in `cols` x `rows` with the given gaps (image pixels) between them. */
export function repeatCommand(seg, id, {cols, rows, gapX, gapY}) {
  const r = seg.get(id);
  return repeatRects(seg, id, {cols, rows, dx: r.x1 - r.x0 + gapX, dy: r.y1 - r.y0 + gapY});
}

/** What "Repeat" does with the selection `ids` ({cols, rows, gapX, gapY} as typed): {command, message} when one
 * rectangle is selected and some copy fits in the image, else {error}; both messages name what was there. */
export function repeatSelection(seg, ids, options) {
  if (ids.length !== 1) {
    const two = ids.length === 2 ? ', or "Repeat to the edge" to repeat the two at their pitch' : "";
    return {error: ids.length ? `Repeat copies one rectangle, and ${ids.length} are selected: select one of them${two}.`
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
  if (!made) {
    return {error: wanted ? "Not repeated: no copy would lie inside the image."
      : "Not repeated: 1 × 1 is the rectangle itself."};
  }
  const left = wanted > made ? `; ${wanted - made} outside the image left out` : "";
  return {command, message: `Added ${made} ${label} ${made === 1 ? "copy" : "copies"} (${cols} × ${rows})${left}.`};
}

const MAX_COPIES = 2000;
const area = (r) => (r.x1 - r.x0) * (r.y1 - r.y0);
const overlap = (a, b) => Math.max(0, Math.min(a.x1, b.x1) - Math.max(a.x0, b.x0)) *
  Math.max(0, Math.min(a.y1, b.y1) - Math.max(a.y0, b.y0));
const inside = (r, b) => r.x0 >= b.x0 && r.y0 >= b.y0 && r.x1 <= b.x1 && r.y1 <= b.y1;

/** Where copies may go: the bounds of the facade rectangles that hold the examples' centres (a facade drawn in
 * pieces counts whole), else the whole image. {x0, y0, x1, y1, facade: whether facades gave it}. */
export function facadeBounds(seg, examples) {
  const centres = examples.map((r) => [(r.x0 + r.x1) / 2, (r.y0 + r.y1) / 2]);
  const walls = [...seg.rects.values()].filter((f) => f.label === "facade" && !examples.includes(f) &&
    centres.some(([x, y]) => contains(f, x, y)));
  if (!walls.length) return {x0: 0, y0: 0, x1: seg.width, y1: seg.height, facade: false};
  return {x0: Math.min(...walls.map((f) => f.x0)), y0: Math.min(...walls.map((f) => f.y0)),
    x1: Math.max(...walls.map((f) => f.x1)), y1: Math.max(...walls.map((f) => f.y1)), facade: true};
}

const FOLLOW = 0.6;  // how alike the first example a place of the photo must look to take a copy
const REACH = 0.25;  // of the pitch: how far from where the pitch puts it a copy's place is looked for

/** Copies of two examples of one class at their pitch (the second's offset from the first), both ways along it
 * until they would leave the facade (`facadeBounds`); a place where that class is already drawn (half the copy
 * covered) is skipped. With the photo's gray levels (`gray`), each copy goes where the photo shows one, looked for
 * within `REACH` of the pitch from the last (`matchNear`: a facade's bays are rarely evenly spaced), and the copies
 * stop where it shows none. {command, message} or {error}. */
export function repeatByPitch(seg, ids, gray = null) {
  if (ids.length !== 2) {
    return {error: `Repeat to the edge measures the pitch between two rectangles of one class, and ${ids.length} ` +
      `${ids.length === 1 ? "is" : "are"} selected.`};
  }
  const [a, b] = ids.map((id) => seg.get(id)).sort((p, q) => p.y0 - q.y0 || p.x0 - q.x0);
  if (a.label !== b.label) return {error: `The two are a ${a.label} and a ${b.label}: select two of one class.`};
  if (intersects(a, b)) return {error: "The two overlap: select two separate elements, one pitch apart."};
  const [dx, dy] = [b.x0 - a.x0, b.y0 - a.y0];
  const bounds = facadeBounds(seg, [a, b]);
  const same = [...seg.rects.values()].filter((r) => r.label === a.label);
  const reach = {x: Math.round(REACH * Math.abs(dx)) + 2, y: Math.round(REACH * Math.abs(dy)) + 2};
  const copies = [];
  let skipped = 0, unseen = 0;
  for (const [from, sign] of [[b, 1], [a, -1]]) {
    for (let last = from; copies.length < MAX_COPIES;) {
      let c = translate(last, sign * dx, sign * dy);
      if (!inside(c, bounds)) break;
      if (gray) {
        const found = matchNear(gray, a, c, reach);
        if (!found || found.score < FOLLOW || !inside(found, bounds)) {
          unseen++;
          break;
        }
        c = {x0: found.x0, y0: found.y0, x1: found.x1, y1: found.y1};
      }
      if (same.some((r) => overlap(r, c) * 2 >= area(c))) skipped++;
      else copies.push({label: a.label, ...c});
      last = c;
    }
  }
  const edge = bounds.facade ? "the facade's edge" : "the image's edge";
  const had = skipped ? `; ${skipped} ${skipped === 1 ? "place" : "places"} already had one` : "";
  const none = unseen ? `where it shows none (${unseen === 1 ? "one way" : "both ways"}) or ` : "";
  const where = gray ? ` where the photo shows one, up to ${none}${edge}` : `, to ${edge}`;
  if (!copies.length) {
    return {error: `Nothing added: no free place at a pitch of ${dx}, ${dy} px${gray ? " that the photo shows" : ""} ` +
      `before ${edge}${had}.`};
  }
  return {command: new AddRects(copies, "repeat to the edge"), message: `Added ${copies.length} ${a.label} ` +
    `${copies.length === 1 ? "copy" : "copies"} at a pitch of ${gray ? "about " : ""}${dx}, ${dy} px${where}${had}.`};
}

/** Rectangle `id` cut into `n` columns or rows (`direction`) with `gap` whole pixels between them, replacing it in
 * one step; the pieces share its class and tile it edge to edge. {command, message} or {error}. */
export function splitCommand(seg, ids, {n, direction, gap}) {
  if (ids.length !== 1) return {error: `Split cuts one rectangle, and ${ids.length} are selected.`};
  if (!Number.isInteger(n) || n < 2 || n > 200) return {error: "Split needs a whole number of pieces from 2 to 200."};
  if (!Number.isInteger(gap) || gap < 0) return {error: "The gap must be a whole number of pixels, 0 or more."};
  const r = seg.get(ids[0]);
  const [lo, hi] = direction === "rows" ? ["y0", "y1"] : ["x0", "x1"];
  const side = r[hi] - r[lo], piece = (side - (n - 1) * gap) / n;
  if (piece < 1) return {error: `${n} ${direction} with gaps of ${gap} px do not fit in ${side} px.`};
  const pieces = Array.from({length: n}, (_, i) => ({label: r.label, x0: r.x0, y0: r.y0, x1: r.x1, y1: r.y1,
    [lo]: r[lo] + Math.round(i * (piece + gap)), [hi]: r[lo] + Math.round(i * (piece + gap) + piece)}));
  return {command: new Batch([new DeleteRects([r.id]), new AddRects(pieces)], "split"),
    message: `Split the ${r.label} into ${n} ${direction}${gap ? ` with gaps of ${gap} px` : ""}.`};
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
 * propose them again; a dimmed one left as it came (not taken) was never proposed, and is not rejected. */
export function rejectedOf(proposals) {
  return proposals.filter((p) => p.accepted === false && !p.dimmed)
    .map(({label, x0, y0, x1, y1}) => ({label, x0, y0, x1, y1}));
}
