// The selection's exact numbers: typed values become one undoable command, bad ones are refused with the field.
import assert from "node:assert/strict";
import {test} from "node:test";

import {AddRects} from "../editor/commands.js";
import {History} from "../editor/history.js";
import {boxFields, setBoxCommand} from "../editor/inspect.js";
import {Segmentation} from "../editor/state.js";

function scene() {
  const seg = new Segmentation(200, 100);
  const history = new History(seg);
  history.execute(new AddRects([{label: "window", x0: 20, y0: 20, x1: 40, y1: 50}]));
  return {seg, history};
}

test("exact box: the fields show the box; typed numbers are one command, undone in one step", () => {
  const {seg, history} = scene();
  assert.deepEqual(boxFields(seg.get(1)), {x0: "20", y0: "20", x1: "40", y1: "50"});
  const {command} = setBoxCommand(seg, 1, {x0: " 25", y0: "10", x1: "45 ", y1: "100"});
  history.execute(command);
  assert.deepEqual(seg.get(1), {id: 1, label: "window", x0: 25, y0: 10, x1: 45, y1: 100});
  history.undo();
  assert.deepEqual(seg.get(1), {id: 1, label: "window", x0: 20, y0: 20, x1: 40, y1: 50});
  assert.deepEqual(setBoxCommand(seg, 1, boxFields(seg.get(1))), {command: null});
});

test("exact box: not whole numbers, outside the image or inside out are refused with the field", () => {
  const {seg} = scene();
  const typed = (changes) => setBoxCommand(seg, 1, {x0: "20", y0: "20", x1: "40", y1: "50", ...changes}).error;
  assert.equal(typed({x0: "2.5"}), 'x0 must be a whole number of pixels, not "2.5".');
  assert.equal(typed({y1: ""}), 'y1 must be a whole number of pixels, not "".');
  assert.equal(typed({x0: "1e3"}), 'x0 must be a whole number of pixels, not "1e3".');
  assert.equal(typed({x0: "-1"}), "x0 must be at least 0, not -1.");
  assert.equal(typed({x1: "201"}), "x1 must be at most the image's width, 200, not 201.");
  assert.equal(typed({y1: "101"}), "y1 must be at most the image's height, 100, not 101.");
  assert.equal(typed({x1: "20"}), "x1 must be greater than x0 (20), not 20.");
  assert.equal(typed({y0: "60"}), "y1 must be greater than y0 (60), not 50.");
});
