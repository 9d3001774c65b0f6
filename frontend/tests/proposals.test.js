// Proposals in groups: a unit's copies, the rows and columns the chips stand for, and the unit sent to the server.
import assert from "node:assert/strict";
import {test} from "node:test";

import {AddRects} from "../editor/commands.js";
import {History} from "../editor/history.js";
import {chipAt, chipMembers, chips, copyOf, lines, toggleRejected, unitIndices} from "../editor/proposals.js";
import {Segmentation} from "../editor/state.js";

/** Copies of a window with its sill on a 3 x 2 lattice (pitch 100 x 120), as "Find copies" answers. */
function copies() {
  const out = [];
  let copy = 0;
  for (let j = 0; j < 2; j++) {
    for (let i = 0; i < 3; i++) {
      const x = 20 + 100 * i, y = 20 + 120 * j;
      out.push({label: "window", x0: x, y0: y, x1: x + 50, y1: y + 80, score: 0.9 - copy / 100, copy,
        reason: "copy of the unit"});
      out.push({label: "sill", x0: x - 5, y0: y + 80, x1: x + 55, y1: y + 86, score: 0.9 - copy / 100, copy,
        reason: "copy of the unit"});
      copy++;
    }
  }
  return out;
}

test("rows and columns are lines of one class whose middles agree within half their size", () => {
  const p = copies();
  const rows = lines(p, "y");
  assert.equal(rows.length, 4);  // two rows of windows, two of sills
  assert.deepEqual(rows.filter((l) => l[0].label === "window").map((l) => l.map((q) => q.x0)),
    [[20, 120, 220], [20, 120, 220]]);
  const columns = lines(p.filter((q) => q.label === "window"), "x");
  assert.deepEqual(columns.map((l) => l.map((q) => q.y0)), [[20, 140], [20, 140], [20, 140]]);
  assert.deepEqual(lines([p[0]], "y"), []);  // a line is two or more
});

test("the chips sit left of each row and above each column of windows, in screen pixels", () => {
  const p = copies();
  const list = chips(p, (x, y) => [2 * x + 10, 2 * y]);  // zoomed 2x, panned 10 px
  assert.deepEqual(list.map((c) => c.kind), ["row", "row", "column", "column", "column"]);
  const [row] = list;
  assert.equal(row.x + row.w + 4, 2 * 20 + 10);  // its right edge 4 px left of the row's first window
  assert.equal(row.y + row.h / 2, 2 * (20 + 40));  // centred on it
  assert.equal(chipAt(list, row.x + 1, row.y + 1), row);
  assert.equal(chipAt(list, 0, 0), undefined);
  // a row's chip stands for its windows and their sills
  assert.deepEqual(chipMembers(p, row).map((q) => `${q.label}${q.copy}`).sort(),
    ["sill0", "sill1", "sill2", "window0", "window1", "window2"]);
});

test("a click rejects a copy whole; a second takes it back; without copies one proposal alone", () => {
  const p = copies();
  const mates = copyOf(p, p[2]);
  assert.deepEqual(mates, [p[2], p[3]]);
  assert.equal(toggleRejected(mates), true);
  assert.ok(mates.every((q) => q.accepted === false) && p[0].accepted === undefined);
  assert.equal(toggleRejected(mates), false);
  assert.ok(mates.every((q) => q.accepted === true));
  const alone = {label: "window", x0: 0, y0: 0, x1: 5, y1: 5, reason: "grid"};
  assert.deepEqual(copyOf([alone, ...p], alone), [alone]);
  // partly rejected: a click rejects the rest
  p[0].accepted = false;
  assert.equal(toggleRejected([p[0], p[1]]), true);
  assert.ok(p[1].accepted === false);
});

test("the unit is the selection's indices in the segmentation's JSON, which lists rectangles in paint order", () => {
  const seg = new Segmentation(300, 300);
  new History(seg).execute(new AddRects([{label: "window", x0: 10, y0: 10, x1: 50, y1: 80},
    {label: "facade", x0: 0, y0: 0, x1: 300, y1: 300}, {label: "sill", x0: 5, y0: 80, x1: 55, y1: 86}]));
  const [win, wall, sill] = [...seg.rects.keys()];
  const json = seg.toJSON().rects;
  const unit = unitIndices(seg, new Set([sill, win]));
  assert.deepEqual(unit.map((i) => json[i].label).sort(), ["sill", "window"]);
  assert.deepEqual(unitIndices(seg, [wall]).map((i) => json[i].label), ["facade"]);
  assert.deepEqual(unitIndices(seg, [999]), []);
});
