// Moving the selection: the selection's bounding box follows the pointer inside the image and snaps to the other
// rectangles' edges; every member moves by the same whole-pixel offset.
import {moveRects} from "../commands.js";
import {moveWithin} from "../geometry.js";
import {snapped} from "./context.js";

export class MoveGesture {
  constructor(pointer, ids) {
    this.kind = "move";
    this.x = pointer.x;
    this.y = pointer.y;
    this.ids = new Set(ids);
    this.dx = 0;
    this.dy = 0;
    this.preview = new Map();  // id -> the rectangle where it would go
  }

  move(pointer, ctx) {
    const boxes = [...this.ids].map((id) => ctx.seg.get(id));
    const bbox = {x0: Math.min(...boxes.map((b) => b.x0)), y0: Math.min(...boxes.map((b) => b.y0)),
      x1: Math.max(...boxes.map((b) => b.x1)), y1: Math.max(...boxes.map((b) => b.y1))};
    const moved = moveWithin(bbox, pointer.x - this.x, pointer.y - this.y, ctx.seg.width, ctx.seg.height);
    const s = snapped(ctx, moved, this.ids, ["x0", "x1", "y0", "y1"], pointer);
    this.dx = Math.round(s.rect.x0 - bbox.x0);
    this.dy = Math.round(s.rect.y0 - bbox.y0);
    this.preview = new Map(boxes.map((b) => [b.id, {...b, x0: b.x0 + this.dx, x1: b.x1 + this.dx,
      y0: b.y0 + this.dy, y1: b.y1 + this.dy}]));
    return {guides: s.guides};
  }

  up(ctx) {
    return this.dx || this.dy ? {command: moveRects(ctx.seg, [...this.ids], this.dx, this.dy)} : {};
  }
}
