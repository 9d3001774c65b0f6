import assert from "node:assert/strict";
import {test} from "node:test";

import {isWithin, leafAt, leavesUnder, parametersOf, pictureToProcedure} from "../procedure/selection.js";

// a floor of two tiles (root/1/0 repeated), each a window over a sill, under an attic band
const leaves = [
  ["cornice", 0, 0, 100, 20, "root/0"],
  ["facade", 0, 20, 10, 60, "root/1/0/0"],
  ["window", 10, 20, 40, 50, "root/1/0/1/0"],
  ["sill", 10, 50, 40, 60, "root/1/0/1/1"],
  ["facade", 50, 20, 60, 60, "root/1/0/0"],
  ["window", 60, 20, 90, 50, "root/1/0/1/0"],
  ["sill", 60, 50, 90, 60, "root/1/0/1/1"],
];
const parameters = [
  {name: "floor_height", nodes: ["root/1"]},
  {name: "tile_width", nodes: ["root/1/0"]},
  {name: "window_width", nodes: ["root/1/0/1"]},
  {name: "attic_height", nodes: ["root/0"]},
  {name: "width", nodes: ["root"]},
];

test("a path lies within itself and its ancestors, not within a sibling that shares its prefix", () => {
  assert.ok(isWithin("root/1/0", "root/1"));
  assert.ok(isWithin("root/1", "root/1"));
  assert.ok(!isWithin("root/10", "root/1"));
  assert.ok(!isWithin("root/1", "root/1/0"));
});

test("the leaf under a point, edges half open", () => {
  assert.equal(leafAt(leaves, 25, 30)[0], "window");
  assert.equal(leafAt(leaves, 45, 55), null);  // between the tiles nothing is drawn here
  assert.equal(leafAt(leaves, 10, 20)[5], "root/1/0/1/0");
  assert.equal(leafAt(leaves, 9.99, 20)[5], "root/1/0/0");
  assert.equal(leafAt(leaves, 100, 0), null);
});

test("a node stands for every copy of its leaves", () => {
  assert.deepEqual(leavesUnder(leaves, ["root/1/0/1"]).map((l) => l[0]), ["window", "sill", "window", "sill"]);
  assert.equal(leavesUnder(leaves, ["root/0", "root/1/0/0"]).length, 3);
  assert.equal(leavesUnder(leaves, ["root"]).length, leaves.length);
});

test("the parameters of a leaf, innermost first", () => {
  assert.deepEqual(parametersOf(parameters, "root/1/0/1/0"), ["window_width", "tile_width", "floor_height", "width"]);
  assert.deepEqual(parametersOf(parameters, "root/0"), ["attic_height", "width"]);
  assert.deepEqual(parametersOf([{name: "floors", nodes: ["root/2"]}], "root/1/0"), []);
});

test("a pointer on a picture shown at another size names the procedure's pixel", () => {
  assert.deepEqual(pictureToProcedure(50, 25, 200, 100, 400, 200), [100, 50]);
});
