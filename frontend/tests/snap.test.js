// Snapping in screen pixels: the same few pixels on the screen at any zoom, only the edges the pointer drags, and a
// guide wherever an edge snapped.
import assert from "node:assert/strict";
import {test} from "node:test";

import {AddRects} from "../editor/commands.js";
import {History} from "../editor/history.js";
import {Segmentation} from "../editor/state.js";
import {SNAP_PX} from "../editor/tools/context.js";
import {press} from "../editor/tools/select.js";

function scene() {
  const seg = new Segmentation(400, 300);
  new History(seg).execute(new AddRects([{label: "window", x0: 100, y0: 100, x1: 140, y1: 160}]));
  return seg;
}
const at = (x, y, scale, mods = {}) => ({x, y, sx: x * scale, sy: y * scale, shift: false, alt: false, ...mods});
const context = (seg, scale, extra = {}) => ({seg, selection: new Set(), label: "door", scale, snap: true, ...extra});

// draw from far away to a far corner `d` image pixels right of the window's right edge (x = 140)
function drawTo(seg, scale, d) {
  const ctx = context(seg, scale);
  const g = press("draw", at(200, 250, scale), ctx, {}).gesture;
  const {guides} = g.move(at(140 + d, 200, scale), ctx);
  return {x: g.rect.x0, guides};
}

test("snap: the distance is SNAP_PX screen pixels, whatever the zoom", () => {
  const seg = scene();
  assert.ok(SNAP_PX >= 3 && SNAP_PX <= 8);
  for (const scale of [0.25, 1, 4]) {
    const near = (SNAP_PX - 1) / scale, far = (SNAP_PX + 2) / scale;  // image pixels
    const snapped = drawTo(seg, scale, near);
    assert.equal(snapped.x, 140, `scale ${scale}`);
    assert.deepEqual(snapped.guides, [{axis: "x", at: 140}]);
    const free = drawTo(seg, scale, far);
    assert.equal(free.x, 140 + far, `scale ${scale}`);
    assert.deepEqual(free.guides, []);
  }
});

test("snap: a draw snaps the corner the pointer drags, never the corner it started from", () => {
  const seg = scene();
  const ctx = context(seg, 1);
  const g = press("draw", at(143, 103, 1), ctx, {}).gesture;  // starts 3 px from the window's corner
  g.move(at(250, 250, 1), ctx);
  assert.deepEqual(g.rect, {x0: 143, y0: 103, x1: 250, y1: 250});
});

test("snap: a resize snaps the edge its handle drags, not the edges beside it", () => {
  const seg = scene();
  seg.insert({label: "door", x0: 200, y0: 103, x1: 260, y1: 157});  // 3 px inside the window's top and bottom
  const ctx = context(seg, 1, {selection: new Set([2])});
  const p = press("select", at(260, 130, 1), ctx, {});  // the door's east handle
  assert.equal(p.gesture.kind, "resize");
  p.gesture.move(at(300, 130, 1), ctx);
  assert.deepEqual(p.gesture.preview.get(2), {id: 2, label: "door", x0: 200, y0: 103, x1: 300, y1: 157});
});

test("snap: a handle dragged across the opposite edge snaps itself, and the edge left behind stays", () => {
  const seg = scene();
  seg.insert({label: "door", x0: 143, y0: 200, x1: 180, y1: 240});  // west edge 3 px from the window's right edge
  const ctx = context(seg, 1, {selection: new Set([2])});
  const p = press("select", at(180, 220, 1), ctx, {});  // the east handle, dragged to the west past x0
  p.gesture.move(at(97, 220, 1), ctx);  // 3 px left of the window's left edge at 100
  assert.deepEqual(p.gesture.preview.get(2), {id: 2, label: "door", x0: 100, y0: 200, x1: 143, y1: 240});
});

test("snap: a move snaps the nearer edge of the dragged box and keeps its size, with its guide", () => {
  const seg = scene();
  seg.insert({label: "door", x0: 200, y0: 200, x1: 220, y1: 240});
  const ctx = context(seg, 2, {selection: new Set([2])});
  const p = press("select", at(210, 220, 2), ctx, {});
  const {guides} = p.gesture.move(at(210 - 78.5, 220 + 12, 2), ctx);  // x1 lands 1.5 image px right of x = 140
  assert.deepEqual(p.gesture.preview.get(2), {id: 2, label: "door", x0: 120, y0: 212, x1: 140, y1: 252});
  assert.deepEqual(guides, [{axis: "x", at: 140}]);
});
