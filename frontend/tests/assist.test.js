// The assistants' commands and the messages they leave: what the user sees must name what was selected and done.
import assert from "node:assert/strict";
import {test} from "node:test";

import {proposalAt, repeatSelection} from "../assist.js";
import {AddRects} from "../commands.js";
import {History} from "../history.js";
import {Segmentation} from "../state.js";

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
    {error: "Repeat copies one rectangle, and 2 are selected: select one of them."});
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
