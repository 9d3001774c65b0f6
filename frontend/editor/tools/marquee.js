// Selecting by a box: every rectangle it touches joins the selection, except the facade rectangles, which lie
// under everything and would always be caught, and the hidden and locked classes. A box started on the wall and
// not dragged is a click on it: it selects that facade rectangle (Shift: adds or removes it).
import {intersects, normalize} from "../geometry.js";
import {pickable} from "../objects.js";

const CLICK_PX = 3;  // a box no larger than this on the screen is a click

export class MarqueeGesture {
  constructor(pointer, wall = null) {
    this.kind = "marquee";
    this.box = {x0: pointer.x, y0: pointer.y, x1: pointer.x, y1: pointer.y};
    this.wall = wall ?? null;  // the facade rectangle it started on, if any
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
    if (this.wall !== null && Math.max(box.x1 - box.x0, box.y1 - box.y0) * (ctx.scale ?? 1) <= CLICK_PX) {
      if (selection.has(this.wall)) selection.delete(this.wall);
      else selection.add(this.wall);
      return {selection};
    }
    for (const r of ctx.seg.rects.values()) {
      if (intersects(r, box) && r.label !== "facade" && pickable(ctx.layers, r)) selection.add(r.id);
    }
    return {selection};
  }
}
