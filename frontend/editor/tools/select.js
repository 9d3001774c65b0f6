// What a press starts, by tool and by what lies under the pointer: the gesture and the selection it leaves.
//   - Space or the middle button: pan;
//   - on a handle of the one selected rectangle: resize it (with the draw tool, only a press on the rectangle);
//   - the draw tool: draw;
//   - the select tool, on a rectangle: select it (Shift toggles it) and move the selection; a press inside the
//     selection grabs it even where another class paints on top;
//   - the select tool, on nothing or on the wall (a facade rectangle, which lies under everything): a marquee (Shift
//     keeps the selection); a click on the wall without a drag selects the facade rectangle;
//   - Shift never resizes: it adds or removes what it presses on (a thin sill under a selected window, within
//     reach of the window's handle).
// Hidden and locked classes (ctx.layers) are passed through.
import {contains, handleAt} from "../geometry.js";
import {pickable} from "../objects.js";
import {HANDLE_PX} from "./context.js";
import {DrawGesture} from "./draw.js";
import {MarqueeGesture} from "./marquee.js";
import {MoveGesture} from "./move.js";
import {PanGesture} from "./pan.js";
import {ResizeGesture} from "./resize.js";

/** {gesture, selection}: the gesture to feed the pointer's moves, and the selection from now on. */
export function press(tool, pointer, ctx, view, {pan = false} = {}) {
  const selection = new Set(ctx.selection);
  if (pan) return {gesture: new PanGesture(pointer, view), selection};
  if (selection.size === 1 && !pointer.shift) {
    const id = [...selection][0], r = ctx.seg.get(id);
    const handle = handleAt(r, pointer.x, pointer.y, HANDLE_PX / ctx.scale);
    // with the draw tool only a press on the rectangle itself resizes it: beside it (a window 8 px from the one just
    // drawn), a drag draws, at any zoom
    if (handle && (tool !== "draw" || onRect(r, pointer.x, pointer.y))) {
      return {gesture: new ResizeGesture(id, handle), selection};
    }
  }
  if (tool === "draw") return {gesture: new DrawGesture(pointer), selection};
  const inside = [...selection].map((id) => ctx.seg.get(id)).find((r) => contains(r, pointer.x, pointer.y));
  // hidden and locked classes are not hit: a press goes through them to what lies below
  const hit = inside && !pointer.shift ? inside : ctx.seg.topAt(pointer.x, pointer.y, (r) => pickable(ctx.layers, r));
  if (!hit || (hit.label === "facade" && !inside)) {
    if (!pointer.shift) selection.clear();
    return {gesture: new MarqueeGesture(pointer, hit?.id), selection};
  }
  if (pointer.shift) {
    if (selection.has(hit.id)) selection.delete(hit.id);
    else selection.add(hit.id);
  } else if (!selection.has(hit.id)) {
    selection.clear();
    selection.add(hit.id);
  }
  return {gesture: new MoveGesture(pointer, selection), selection};
}

const onRect = (r, x, y) => x >= r.x0 && x <= r.x1 && y >= r.y0 && y <= r.y1;  // its edges included
