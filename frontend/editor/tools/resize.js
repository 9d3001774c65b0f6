// Resizing one rectangle by a handle: the handle's edges follow the pointer and snap; the rest stays.
import {UpdateRects} from "../commands.js";
import {clampToImage, dragEdges} from "../geometry.js";
import {snapped} from "./context.js";

export class ResizeGesture {
  constructor(id, handle) {
    this.kind = "resize";
    this.id = id;
    this.handle = handle;
    this.preview = new Map();
  }

  move(pointer, ctx) {
    const r = ctx.seg.get(this.id);
    const edges = [];
    if (this.handle.includes("n")) edges.push("y0");
    if (this.handle.includes("s")) edges.push("y1");
    if (this.handle.includes("w")) edges.push("x0");
    if (this.handle.includes("e")) edges.push("x1");
    // snapped before normalizing: past the opposite edge the dragged edge is still the one named by the handle
    const s = snapped(ctx, dragEdges(r, this.handle, pointer.x, pointer.y), new Set([this.id]), edges, pointer);
    const box = clampToImage(s.rect, ctx.seg.width, ctx.seg.height);  // normalizes
    this.preview = box ? new Map([[this.id, {...r, ...box}]]) : new Map();
    return {guides: s.guides};
  }

  up() {
    const r = this.preview.get(this.id);
    if (!r) return {};
    return {command: new UpdateRects([{id: this.id, after: {x0: r.x0, y0: r.y0, x1: r.x1, y1: r.y1}}], "resize")};
  }
}
