// Drawing a new rectangle of the current class: dragged from one corner to the other, the far corner snapped.
import {AddRects} from "../commands.js";
import {clampToImage, normalize} from "../geometry.js";
import {snapped} from "./context.js";

export const MIN_SIZE = 2;  // image pixels: a click or a slip draws nothing

export class DrawGesture {
  constructor(pointer) {
    this.kind = "draw";
    this.x0 = pointer.x;
    this.y0 = pointer.y;
    this.rect = null;  // the preview, image pixels
  }

  move(pointer, ctx) {
    const s = snapped(ctx, {x0: this.x0, y0: this.y0, x1: pointer.x, y1: pointer.y}, new Set(), ["x1", "y1"], pointer);
    this.rect = normalize(s.rect);
    return {guides: s.guides};
  }

  /** The command that adds the rectangle (its ids become the selection), or nothing for a click. */
  up(ctx) {
    const box = this.rect && clampToImage(this.rect, ctx.seg.width, ctx.seg.height);
    if (!box || box.x1 - box.x0 < MIN_SIZE || box.y1 - box.y0 < MIN_SIZE) return {};
    return {command: new AddRects([{label: ctx.label, ...box}], "draw"), selectAdded: true};
  }
}
