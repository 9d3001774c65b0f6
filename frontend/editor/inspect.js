// A single selected rectangle's exact numbers: its box as the fields show it, and the command that sets what was
// typed, or the reason it is refused. No DOM.
import {UpdateRects} from "./commands.js";

export const BOX_FIELDS = ["x0", "y0", "x1", "y1"];

/** The fields' text for rectangle `r`: {x0: "60", ...}. */
export const boxFields = (r) => Object.fromEntries(BOX_FIELDS.map((k) => [k, String(r[k])]));

/** {command} setting rectangle `id` to the typed box ({x0, y0, x1, y1} as text, image pixels, x1 and y1 past
 * the last pixel as everywhere), {command: null} when it is the box already, or {error} naming the bad field. */
export function setBoxCommand(seg, id, typed) {
  const box = {};
  for (const k of BOX_FIELDS) {
    const text = String(typed[k] ?? "").trim();
    if (!/^-?\d+$/.test(text)) return {error: `${k} must be a whole number of pixels, not "${text}".`};
    box[k] = Number(text);
  }
  const limits = {x: ["width", seg.width], y: ["height", seg.height]};
  for (const axis of ["x", "y"]) {
    const [lo, hi] = [box[`${axis}0`], box[`${axis}1`]], [name, size] = limits[axis];
    if (lo < 0) return {error: `${axis}0 must be at least 0, not ${lo}.`};
    if (hi > size) return {error: `${axis}1 must be at most the image's ${name}, ${size}, not ${hi}.`};
    if (hi <= lo) return {error: `${axis}1 must be greater than ${axis}0 (${lo}), not ${hi}.`};
  }
  const r = seg.get(id);
  if (BOX_FIELDS.every((k) => r[k] === box[k])) return {command: null};
  return {command: new UpdateRects([{id, after: box}], "exact box")};
}
