// What every tool reads, without the DOM: the segmentation, the selection, the class to draw, the view's scale
// (for tolerances given in screen pixels), whether snapping is on, and the classes hidden or locked (`layers`,
// objects.js). A pointer is {x, y} in image pixels and {sx, sy} in screen pixels, with the modifier keys
// {shift, alt}.
import {snap} from "../geometry.js";
import {shown} from "../objects.js";

export const SNAP_PX = 6;  // screen pixels
export const HANDLE_PX = 6;

/** The rectangle snapped to the other rectangles' edges (all but `ids`), or as it is with Alt or snapping off. */
export function snapped(ctx, rect, ids, edges, pointer) {
  if (pointer.alt || !ctx.snap) return {rect, guides: []};
  // edges of hidden classes are not there to see, so nothing snaps to them
  const others = [...ctx.seg.rects.values()].filter((r) => !ids.has(r.id) && shown(ctx.layers, r));
  return snap(rect, others, SNAP_PX / ctx.scale, edges, ctx.seg);
}
