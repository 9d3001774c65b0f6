import assert from "node:assert/strict";
import {test} from "node:test";

import {AddRects, DeleteRects, ReplaceAll, UpdateRects, duplicateRects, moveRects, repeatRects, setLabel}
  from "../editor/commands.js";
import {History} from "../editor/history.js";
import {Segmentation, SegmentationError} from "../editor/state.js";

function fresh() {
  const seg = new Segmentation(100, 80);
  const history = new History(seg);
  history.execute(new AddRects([{label: "facade", x0: 0, y0: 0, x1: 100, y1: 80},
    {label: "window", x0: 10, y0: 10, x1: 20, y1: 30}]));
  return {seg, history};
}

const snapshot = (seg) => JSON.stringify(seg.toJSON());

function roundTrip(seg, history, cmd) {
  const before = snapshot(seg);
  history.execute(cmd);
  const after = snapshot(seg);
  assert.notEqual(after, before);
  history.undo();
  assert.equal(snapshot(seg), before);
  history.redo();
  assert.equal(snapshot(seg), after);
  return after;
}

test("add, and its undo and redo keep ids", () => {
  const {seg, history} = fresh();
  assert.equal(seg.size, 2);
  const cmd = history.execute(new AddRects([{label: "door", x0: 40, y0: 50, x1: 55, y1: 80}]));
  const id = cmd.ids[0];
  history.undo();
  assert.equal(seg.size, 2);
  history.redo();
  assert.equal(seg.get(id).label, "door");
});

test("every command undoes and redoes exactly", () => {
  const {seg, history} = fresh();
  roundTrip(seg, history, new DeleteRects([2]));
  history.undo();
  roundTrip(seg, history, moveRects(seg, [2], 5, 7));
  roundTrip(seg, history, setLabel([2], "blind"));
  roundTrip(seg, history, new UpdateRects([{id: 2, after: {x0: 12, y0: 11, x1: 30, y1: 40}}], "resize"));
  roundTrip(seg, history, duplicateRects(seg, [2], 15, 0));
  roundTrip(seg, history, repeatRects(seg, 2, {cols: 4, dx: 20}));
  roundTrip(seg, history, new ReplaceAll([{label: "shop", x0: 0, y0: 60, x1: 100, y1: 80}]));
});

test("repeat drops copies outside the image and keeps the label", () => {
  const {seg, history} = fresh();
  const cmd = history.execute(repeatRects(seg, 2, {cols: 10, dx: 20}));
  assert.equal(cmd.ids.length, 4);  // x0 = 30, 50, 70, 90 fit in 100 px (the last is clipped)
  assert.ok(cmd.ids.every((id) => seg.get(id).label === "window"));
  assert.equal(seg.get(cmd.ids[3]).x1, 100);
});

test("a failing command changes nothing and is not recorded", () => {
  const {seg, history} = fresh();
  const before = snapshot(seg);
  assert.throws(() => history.execute(new AddRects([{label: "ufo", x0: 0, y0: 0, x1: 5, y1: 5}])), /unknown label/);
  assert.throws(() => history.execute(new DeleteRects([99])), /no rectangle/);
  assert.equal(snapshot(seg), before);
  assert.equal(history.done.length, 1);
});

test("history: cap, redo cleared by a new command, dirty tracking", () => {
  const seg = new Segmentation(50, 50);
  const history = new History(seg, 3);
  assert.equal(history.dirty, false);
  for (let i = 0; i < 5; i++) history.execute(new AddRects([{label: "window", x0: i, y0: 0, x1: i + 2, y1: 4}]));
  assert.equal(history.done.length, 3);
  assert.equal(history.dirty, true);
  history.markSaved();
  assert.equal(history.dirty, false);
  history.undo();
  assert.equal(history.dirty, true);
  history.redo();
  assert.equal(history.dirty, false);
  history.undo();
  history.execute(new AddRects([{label: "door", x0: 0, y0: 10, x1: 5, y1: 20}]));
  assert.equal(history.canRedo, false);
  assert.equal(history.dirty, true);
  let calls = 0;
  history.onChange(() => calls++);
  history.undo();
  assert.equal(calls, 1);
});

test("JSON import validates and export follows the paint order", () => {
  const seg = Segmentation.fromJSON({width: 20, height: 10, rects: [
    {label: "window", x0: 2, y0: 2, x1: 5, y1: 5}, {label: "facade", x0: 0, y0: 0, x1: 20, y1: 10}]});
  assert.deepEqual(seg.toJSON().rects.map((r) => r.label), ["facade", "window"]);
  assert.equal(seg.topAt(3, 3).label, "window");
  assert.equal(seg.topAt(10, 8).label, "facade");
  for (const [bad, message] of [
    [[], /JSON object/], [{width: -1, height: 5, rects: []}, /whole numbers/],
    [{width: 10, height: 10, rects: "x"}, /list/],
    [{width: 10, height: 10, rects: [{label: "window", x0: 0, y0: 0, x1: NaN, y1: 3}]}, /x1 must be a number/],
    [{width: 10, height: 10, rects: [{label: "window", x0: 0, y0: 0, x1: 30, y1: 3}]}, /outside/],
    [{width: 10, height: 10, rects: [{label: "tree", x0: 0, y0: 0, x1: 3, y1: 3}]}, /unknown label/],
  ]) {
    assert.throws(() => Segmentation.fromJSON(bad), (err) => err instanceof SegmentationError && message.test(err.message));
  }
});
