// Selecting by a box: every rectangle it touches joins the selection, except the facade rectangles, which lie
// under everything and would always be caught, and the hidden and locked classes.
import {intersects, normalize} from "../geometry.js";
import {pickable} from "../objects.js";

export class MarqueeGesture {
  constructor(pointer) {
    this.kind = "marquee";
    this.box = {x0: pointer.x, y0: pointer.y, x1: pointer.x, y1: pointer.y};
  }

  move(pointer) {
    this.box.x1 = pointer.x;
    this.box.y1 = pointer.y;
    return {guides: []};
  }

  /** The selection afterwards: the one it started from (kept with Shift) and what the box touches. */
  up(ctx) {
    const box = normalize(this.box);
    const selection = new Set(ctx.selection);
    for (const r of ctx.seg.rects.values()) {
      if (intersects(r, box) && r.label !== "facade" && pickable(ctx.layers, r)) selection.add(r.id);
    }
    return {selection};
  }
}
