// The editor's tools without a browser: a press starts the right gesture, moves give previews, a release gives
// the command (or the selection), and the command does what the gesture showed.
import assert from "node:assert/strict";
import {test} from "node:test";

import {acceptCommand, rejectedOf, repeatCommand} from "../editor/assist.js";
import {AddRects} from "../editor/commands.js";
import {History} from "../editor/history.js";
import {keyAction} from "../editor/keys.js";
import {Segmentation} from "../editor/state.js";
import {HANDLE_PX} from "../editor/tools/context.js";
import {press} from "../editor/tools/select.js";
import {PinchGesture, fitView} from "../editor/tools/view.js";

function scene() {
  const seg = new Segmentation(200, 100);
  const history = new History(seg);
  history.execute(new AddRects([{label: "facade", x0: 0, y0: 0, x1: 200, y1: 100},
    {label: "window", x0: 20, y0: 20, x1: 40, y1: 50}, {label: "window", x0: 60, y0: 20, x1: 80, y1: 50}]));
  return {seg, history};
}

const at = (x, y, mods = {}) => ({x, y, sx: x, sy: y, shift: false, alt: false, ...mods});
const context = (seg, extra = {}) => ({seg, selection: new Set(), label: "door", scale: 1, snap: true, ...extra});

test("draw: the far corner snaps to a neighbour's edge within 6 screen pixels, and the command adds it", () => {
  const {seg, history} = scene();
  const ctx = context(seg);
  const {gesture} = press("draw", at(100, 20), ctx, {ox: 0, oy: 0});
  assert.equal(gesture.kind, "draw");
  const moved = gesture.move(at(130, 47), ctx);  // 3 px from the windows' bottom edge at y = 50
  assert.deepEqual(gesture.rect, {x0: 100, y0: 20, x1: 130, y1: 50});
  assert.ok(moved.guides.some((g) => g.axis === "y" && g.at === 50));
  const {command, selectAdded} = gesture.up(ctx);
  history.execute(command);
  assert.ok(selectAdded);
  assert.deepEqual(seg.get(command.ids[0]), {id: command.ids[0], label: "door", x0: 100, y0: 20, x1: 130, y1: 50});
  assert.ok(history.canUndo);
});

test("draw: at a high zoom the same 3 image pixels are too far to snap; Alt turns snapping off; a click draws nothing", () => {
  const {seg} = scene();
  const zoomed = context(seg, {scale: 4});  // 6 screen pixels are 1.5 image pixels
  const g = press("draw", at(100, 20), zoomed, {}).gesture;
  g.move(at(130, 47), zoomed);
  assert.equal(g.rect.y1, 47);
  const plain = context(seg);
  const h = press("draw", at(100, 20), plain, {}).gesture;
  h.move(at(130, 47, {alt: true}), plain);
  assert.equal(h.rect.y1, 47);
  const click = press("draw", at(100, 20), plain, {}).gesture;
  click.move(at(101, 21), plain);
  assert.deepEqual(click.up(plain), {});
});

test("select: a press on a rectangle selects it and moves it; the command moves it by the previewed offset", () => {
  const {seg, history} = scene();
  const ctx = context(seg);
  const {gesture, selection} = press("select", at(30, 30), ctx, {});
  assert.equal(gesture.kind, "move");
  assert.deepEqual([...selection], [2]);
  ctx.selection = selection;
  gesture.move(at(44, 31, {alt: true}), ctx);
  assert.deepEqual(gesture.preview.get(2), {id: 2, label: "window", x0: 34, y0: 21, x1: 54, y1: 51});
  history.execute(gesture.up(ctx).command);
  assert.deepEqual(seg.get(2), {id: 2, label: "window", x0: 34, y0: 21, x1: 54, y1: 51});
  history.undo();
  assert.deepEqual(seg.get(2), {id: 2, label: "window", x0: 20, y0: 20, x1: 40, y1: 50});
});

test("select: Shift adds and removes; a press inside the selection grabs all of it", () => {
  const {seg} = scene();
  let ctx = context(seg, {selection: new Set([2])});
  let {gesture, selection} = press("select", at(70, 30, {shift: true}), ctx, {});
  assert.deepEqual([...selection].sort(), [2, 3]);
  ctx = context(seg, {selection});
  ({gesture, selection} = press("select", at(25, 25), ctx, {}));
  assert.equal(gesture.kind, "move");
  assert.deepEqual([...gesture.ids].sort(), [2, 3]);
  ({selection} = press("select", at(70, 30, {shift: true}), context(seg, {selection}), {}));
  assert.deepEqual([...selection], [2]);
});

test("resize: a press on a handle of the one selected rectangle resizes it, its edge snapping", () => {
  const {seg, history} = scene();
  const ctx = context(seg, {selection: new Set([2])});
  const {gesture} = press("draw", at(40, 35), ctx, {});  // the east handle, even with the draw tool
  assert.equal(gesture.kind, "resize");
  assert.equal(gesture.handle, "e");
  gesture.move(at(57, 35), ctx);  // 3 px from the other window's west edge at x = 60
  assert.deepEqual(gesture.preview.get(2), {id: 2, label: "window", x0: 20, y0: 20, x1: 60, y1: 50});
  history.execute(gesture.up(ctx).command);
  assert.equal(seg.get(2).x1, 60);
});

test("draw: beside the selected rectangle a drag draws, however near its handle at any zoom; on it, it resizes", () => {
  const {seg} = scene();
  for (const scale of [0.25, 0.6, 1, 4]) {
    const ctx = context(seg, {selection: new Set([2]), scale});  // window 2 spans x 20-40, y 20-50
    const beside = HANDLE_PX / scale / 2;  // within the handle's reach, outside the rectangle
    assert.equal(press("draw", at(40 + beside, 20 + beside / 2), ctx, {}).gesture.kind, "draw", `scale ${scale}`);
    assert.equal(press("draw", at(40, 20), ctx, {}).gesture.kind, "resize");  // on its corner
    if (scale >= 0.6) assert.equal(press("draw", at(40 - beside, 35), ctx, {}).gesture.handle, "e");  // inside it
    // the select tool keeps the handle's reach on both sides
    assert.equal(press("select", at(40 + beside, 35), ctx, {}).gesture.kind, "resize");
  }
});

test("marquee: a press on nothing clears the selection (Shift keeps it) and selects what the box touches, no facade", () => {
  const seg = new Segmentation(200, 100);
  new History(seg).execute(new AddRects([{label: "window", x0: 20, y0: 20, x1: 40, y1: 50},
    {label: "window", x0: 60, y0: 20, x1: 80, y1: 50}, {label: "door", x0: 150, y0: 60, x1: 170, y1: 100}]));
  const [a, b, door] = [...seg.rects.values()].map((r) => r.id);
  const cleared = press("select", at(5, 5), context(seg, {selection: new Set([a, door])}), {});
  assert.equal(cleared.gesture.kind, "marquee");
  assert.equal(cleared.selection.size, 0);
  const kept = press("select", at(5, 5, {shift: true}), context(seg, {selection: new Set([door])}), {});
  assert.deepEqual([...kept.selection], [door]);
  kept.gesture.move(at(65, 25));
  const {selection} = kept.gesture.up(context(seg, {selection: kept.selection}));
  assert.deepEqual([...selection].sort(), [a, b, door].sort());
  // a facade rectangle under the box is left out: it lies under everything
  const withFacade = scene().seg;
  const g = press("select", at(190, 95), context(new Segmentation(200, 100)), {}).gesture;
  g.move(at(0, 0));
  assert.deepEqual([...g.up(context(withFacade)).selection].sort(), [2, 3]);
});

test("pan and pinch move the view; fitView centres the image", () => {
  const {seg} = scene();
  const {gesture} = press("select", at(50, 50), context(seg), {ox: 10, oy: 20}, {pan: true});
  assert.equal(gesture.kind, "pan");
  assert.deepEqual(gesture.move({sx: 70, sy: 40}).view, {ox: 30, oy: 10});
  assert.deepEqual(gesture.up(), {});
  const pinch = new PinchGesture([[0, 0], [100, 0]], {scale: 1, ox: 0, oy: 0});
  const v = pinch.view([[-50, 0], [150, 0]]);  // twice as far apart around the same midpoint
  assert.equal(v.scale, 2);
  assert.equal(v.ox, 50 - 50 * 2);  // the image point under the midpoint stays under it
  assert.deepEqual(fitView(200, 100, 400, 400), {scale: 1.9, ox: 10, oy: 105});
});

test("keys: shortcuts map to actions, arrows only with a selection, Enter only with proposals", () => {
  assert.deepEqual(keyAction({key: "z", ctrlKey: true}), {action: "undo"});
  assert.deepEqual(keyAction({key: "Z", ctrlKey: true, shiftKey: true}), {action: "redo"});
  assert.deepEqual(keyAction({key: "r"}), {action: "tool", tool: "draw"});
  assert.deepEqual(keyAction({key: "c"}), {action: "complete"});
  assert.deepEqual(keyAction({key: "F"}), {action: "fit"});
  assert.deepEqual(keyAction({key: "3"}), {action: "label", label: "window"});
  assert.equal(keyAction({key: "ArrowLeft"}, {selected: 0, proposals: 0}), null);
  assert.deepEqual(keyAction({key: "ArrowLeft", shiftKey: true}, {selected: 2, proposals: 0}),
    {action: "nudge", dx: -10, dy: 0});
  assert.equal(keyAction({key: "Enter"}, {selected: 0, proposals: 0}), null);
  assert.deepEqual(keyAction({key: "Enter"}, {selected: 0, proposals: 3}), {action: "accept"});
  assert.equal(keyAction({key: "q", ctrlKey: true}), null);
});

test("assist: a grid of copies with gaps; accepting proposals adds those not rejected", () => {
  const {seg, history} = scene();
  history.execute(repeatCommand(seg, 2, {cols: 3, rows: 1, gapX: 5, gapY: 0}));
  const windows = [...seg.rects.values()].filter((r) => r.label === "window").map((r) => r.x0);
  assert.deepEqual(windows.sort((a, b) => a - b), [20, 45, 60, 70]);
  assert.equal(acceptCommand([{label: "window", x0: 0, y0: 0, x1: 5, y1: 5, accepted: false}]), null);
  const cmd = acceptCommand([{label: "window", x0: 100, y0: 60, x1: 110, y1: 70},
    {label: "window", x0: 0, y0: 0, x1: 5, y1: 5, accepted: false}]);
  history.execute(cmd);
  assert.equal(cmd.ids.length, 1);
  assert.equal(cmd.name, "find similar");
  assert.equal(acceptCommand([{label: "sill", x0: 1, y0: 1, x1: 4, y1: 2}], "complete").name, "complete");
  assert.deepEqual(rejectedOf([{label: "window", x0: 100, y0: 60, x1: 110, y1: 70, score: 0.9},
    {label: "sill", x0: 0, y0: 0, x1: 5, y1: 5, score: 0.9, reason: "grid", accepted: false}]),
  [{label: "sill", x0: 0, y0: 0, x1: 5, y1: 5}]);
});

test("select: a press on the wall starts a box, not a move of the facade; a click on the wall selects it", () => {
  const {seg} = scene();  // a facade rectangle under two windows
  const [facade, a, b] = [...seg.rects.values()].map((r) => r.id);
  const ctx = context(seg, {selection: new Set([a])});
  const {gesture, selection} = press("select", at(10, 10), ctx, {});
  assert.equal(gesture.kind, "marquee");
  assert.equal(selection.size, 0);
  gesture.move(at(90, 60));
  assert.deepEqual([...gesture.up(context(seg, {selection})).selection].sort(), [a, b].sort());  // not the wall
  const click = press("select", at(10, 10), context(seg), {}).gesture;
  click.move(at(11, 11));
  assert.deepEqual([...click.up(context(seg)).selection], [facade]);
  // once selected, a press inside it grabs it as any selection
  assert.equal(press("select", at(10, 10), context(seg, {selection: new Set([facade])}), {}).gesture.kind, "move");
});

test("select: Shift on a thin sill within reach of the selected window's handle adds the sill, not a resize", () => {
  const {seg, history} = scene();
  history.execute(new AddRects([{label: "sill", x0: 18, y0: 50, x1: 42, y1: 53}]));
  const [, a, , sill] = [...seg.rects.values()].map((r) => r.id);
  const ctx = context(seg, {selection: new Set([a])});
  assert.equal(press("select", at(39, 51), ctx, {}).gesture.kind, "resize");  // the window's corner handle
  const {gesture, selection} = press("select", at(39, 51, {shift: true}), ctx, {});
  assert.equal(gesture.kind, "move");
  assert.deepEqual([...selection].sort(), [a, sill].sort());
});

test("assist: a dimmed proposal is not taken until clicked, and never passed back as rejected", () => {
  const dim = {label: "window", x0: 10, y0: 10, x1: 20, y1: 20, score: 0.42, dimmed: true, accepted: false};
  const sure = {label: "window", x0: 40, y0: 10, x1: 50, y1: 20, score: 0.9};
  assert.deepEqual(acceptCommand([dim, sure]).records.map((r) => r.x0), [40]);
  assert.deepEqual(rejectedOf([dim, {...sure, accepted: false}]).map((r) => r.x0), [40]);
  const taken = {...dim, accepted: true};  // clicked: taken
  assert.deepEqual(acceptCommand([taken, sure]).records.map((r) => r.x0), [10, 40]);
});
