// The assistants' commands and the messages they leave: what the user sees must name what was selected and done.
import assert from "node:assert/strict";
import {test} from "node:test";

import {facadeBounds, proposalAt, repeatByPitch, repeatSelection, splitCommand} from "../editor/assist.js";
import {AddRects} from "../editor/commands.js";
import {History} from "../editor/history.js";
import {Segmentation} from "../editor/state.js";

function scene() {
  const seg = new Segmentation(200, 100);
  const history = new History(seg);
  history.execute(new AddRects([{label: "facade", x0: 0, y0: 0, x1: 200, y1: 100},
    {label: "window", x0: 20, y0: 20, x1: 40, y1: 50}, {label: "window", x0: 60, y0: 20, x1: 80, y1: 50}]));
  return {seg, history};
}
const grid = {cols: 3, rows: 1, gapX: 10, gapY: 0};

test("repeat: several or no rectangles selected is refused with the count, and nothing is made", () => {
  const {seg} = scene();
  assert.deepEqual(repeatSelection(seg, [2, 3], grid),
    {error: 'Repeat copies one rectangle, and 2 are selected: select one of them, or "Repeat to the edge" to repeat ' +
      "the two at their pitch."});
  assert.match(repeatSelection(seg, [1, 2, 3], grid).error, /and 3 are selected/);
  assert.match(repeatSelection(seg, [], grid).error, /select one first/);
});

test("repeat: one rectangle gives one command and a message with what it added", () => {
  const {seg, history} = scene();
  const plan = repeatSelection(seg, [2], grid);
  assert.equal(plan.message, "Added 2 window copies (3 × 1).");
  history.execute(plan.command);
  assert.equal(seg.size, 5);
  history.undo();
  assert.equal(seg.size, 3);
});

test("repeat: copies beyond the image are counted in the message; bad counts and gaps are refused", () => {
  const {seg} = scene();
  assert.equal(repeatSelection(seg, [3], {cols: 9, rows: 1, gapX: 20, gapY: 0}).message,
    "Added 3 window copies (9 × 1); 5 outside the image left out.");
  assert.match(repeatSelection(seg, [2], {...grid, cols: 0}).error, /^Not repeated: counts must be whole numbers/);
  assert.match(repeatSelection(seg, [2], {...grid, gapX: NaN}).error, /gaps must be numbers/);
  assert.match(repeatSelection(seg, [2], {cols: 1, rows: 1, gapX: 0, gapY: 0}).error, /the rectangle itself/);
});

test("proposals: the one under a point, half-open like the rectangles", () => {
  const proposals = [{x0: 10, y0: 10, x1: 20, y1: 20}, {x0: 30, y0: 10, x1: 40, y1: 20}];
  assert.equal(proposalAt(proposals, 35, 15), proposals[1]);
  assert.equal(proposalAt(proposals, 20, 15), undefined);
});

// a 300 x 200 image, a facade from x 20 to 280, and two windows 40 px apart on a row
function row() {
  const seg = new Segmentation(300, 200);
  const history = new History(seg);
  history.execute(new AddRects([{label: "facade", x0: 20, y0: 0, x1: 280, y1: 200},
    {label: "window", x0: 100, y0: 50, x1: 120, y1: 80}, {label: "window", x0: 140, y0: 50, x1: 160, y1: 80},
    {label: "door", x0: 60, y0: 150, x1: 80, y1: 200}]));
  return {seg, history};
}
const windows = (seg) => [...seg.rects.values()].filter((r) => r.label === "window").map((r) => r.x0).sort((a, b) => a - b);

test("repeat to the edge: the pitch of two examples, both ways, to the facade's edge, one undo step", () => {
  const {seg, history} = row();
  const plan = repeatByPitch(seg, [3, 2]);  // either order
  assert.equal(plan.message, "Added 5 window copies at a pitch of 40, 0 px, to the facade's edge.");
  history.execute(plan.command);
  assert.deepEqual(windows(seg), [20, 60, 100, 140, 180, 220, 260]);  // the last two touch the facade's edges
  assert.equal(repeatByPitch(new Segmentation(300, 200), []).error.includes("0 are selected"), true);
  history.undo();
  assert.deepEqual(windows(seg), [100, 140]);
});

test("repeat to the edge: without a facade the image's edge; drawn places skipped; diagonal pitches", () => {
  const {seg, history} = row();
  history.execute(new AddRects([{label: "window", x0: 181, y0: 51, x1: 201, y1: 81}]));  // drawn by hand, 1 px off
  const plan = repeatByPitch(seg, [2, 3]);
  assert.equal(plan.message, "Added 4 window copies at a pitch of 40, 0 px, to the facade's edge; 1 place already had one.");
  const bare = new Segmentation(200, 200);
  bare.insert({label: "window", x0: 10, y0: 10, x1: 30, y1: 30});
  bare.insert({label: "window", x0: 50, y0: 60, x1: 70, y1: 80});
  const diagonal = repeatByPitch(bare, [1, 2]);
  assert.equal(diagonal.message, "Added 2 window copies at a pitch of 40, 50 px, to the image's edge.");
  assert.deepEqual(diagonal.command.records.map((r) => [r.x0, r.y0]), [[90, 110], [130, 160]]);
  assert.deepEqual(facadeBounds(bare, []), {x0: 0, y0: 0, x1: 200, y1: 200, facade: false});
});

test("repeat to the edge: refused for other than two, two classes, or overlapping examples", () => {
  const {seg} = row();
  assert.match(repeatByPitch(seg, [2]).error, /between two rectangles of one class, and 1 is selected/);
  assert.match(repeatByPitch(seg, [2, 3, 4]).error, /and 3 are selected/);
  assert.equal(repeatByPitch(seg, [2, 4]).error, "The two are a window and a door: select two of one class.");
  seg.insert({label: "window", x0: 110, y0: 60, x1: 130, y1: 90});
  assert.match(repeatByPitch(seg, [2, 5]).error, /overlap/);
});

test("split: N columns or rows tiling the rectangle, with a gap, replacing it in one undo step", () => {
  const {seg, history} = row();
  const plan = splitCommand(seg, [2], {n: 3, direction: "columns", gap: 1});  // 20 px wide: 6, 6, 6 and two gaps
  assert.equal(plan.message, "Split the window into 3 columns with gaps of 1 px.");
  history.execute(plan.command);
  assert.ok(!seg.rects.has(2));
  assert.deepEqual(plan.command.ids.map((id) => seg.get(id)).map((r) => [r.label, r.x0, r.x1, r.y0, r.y1]),
    [["window", 100, 106, 50, 80], ["window", 107, 113, 50, 80], ["window", 114, 120, 50, 80]]);
  history.undo();
  assert.deepEqual(seg.get(2), {id: 2, label: "window", x0: 100, y0: 50, x1: 120, y1: 80});
  assert.equal(seg.size, 4);
  history.redo();
  assert.equal(seg.size, 6);
  const rows = splitCommand(seg, [4], {n: 4, direction: "rows", gap: 0}).command;  // the door, 50 px high
  history.execute(rows);
  assert.deepEqual(rows.ids.map((id) => [seg.get(id).y0, seg.get(id).y1]), [[150, 163], [163, 175], [175, 188], [188, 200]]);
});

test("split: refused when the pieces do not fit, for bad counts or gaps, and for other than one", () => {
  const {seg} = row();
  assert.equal(splitCommand(seg, [2], {n: 5, direction: "columns", gap: 4}).error,
    "5 columns with gaps of 4 px do not fit in 20 px.");
  assert.match(splitCommand(seg, [2], {n: 1, direction: "rows", gap: 0}).error, /from 2 to 200/);
  assert.match(splitCommand(seg, [2], {n: 2.5, direction: "rows", gap: 0}).error, /from 2 to 200/);
  assert.match(splitCommand(seg, [2], {n: 2, direction: "rows", gap: -1}).error, /0 or more/);
  assert.match(splitCommand(seg, [2, 3], {n: 2, direction: "rows", gap: 0}).error, /and 2 are selected/);
});

test("repeat to the edge with the photo: each copy where the photo shows one, stopping at bare wall", () => {
  // a wall (180) with windows (dark glass, a light cross) whose spacing is uneven: 40 px, then 48 px, then none
  const [w, h, xs] = [300, 100, [20, 60, 108, 148, 196]];
  const data = new Float32Array(w * h).fill(180);
  for (const x0 of xs) {
    for (let y = 30; y < 60; y++) {
      for (let x = x0; x < x0 + 20; x++) data[y * w + x] = x === x0 + 10 || y === 45 ? 200 : 40;
    }
  }
  const seg = new Segmentation(w, h);
  seg.insert({label: "window", x0: 20, y0: 30, x1: 40, y1: 60});
  seg.insert({label: "window", x0: 60, y0: 30, x1: 80, y1: 60});
  const plan = repeatByPitch(seg, [1, 2], {width: w, height: h, data});
  assert.deepEqual(plan.command.records.map((r) => r.x0), [108, 148, 196]);  // not 100, 140, 180, 220, 260
  assert.equal(plan.message, "Added 3 window copies at a pitch of about 40, 0 px where the photo shows one, up to " +
    "where it shows none (one way) or the image's edge.");
  assert.deepEqual(repeatByPitch(seg, [1, 2]).command.records.map((r) => r.x0), [100, 140, 180, 220, 260]);
});
