import assert from "node:assert/strict";
import {test} from "node:test";

import {clampToImage, handleAt, identical, moveWithin, normalize, repeatRect, resize, snap, throughRectification}
  from "../editor/geometry.js";

test("normalize and clamp", () => {
  assert.deepEqual(normalize({x0: 5, y0: 9, x1: 1, y1: 2}), {x0: 1, y0: 2, x1: 5, y1: 9});
  assert.deepEqual(clampToImage({x0: -3, y0: 2.4, x1: 12.6, y1: 50}, 10, 20), {x0: 0, y0: 2, x1: 10, y1: 20});
  assert.equal(clampToImage({x0: 4, y0: 4, x1: 4.2, y1: 9}, 10, 10), null);
  assert.equal(clampToImage({x0: 20, y0: 0, x1: 30, y1: 5}, 10, 10), null);
});

test("move stays within the image and resize by handles", () => {
  assert.deepEqual(moveWithin({x0: 2, y0: 2, x1: 6, y1: 4}, 100, -9, 10, 10), {x0: 6, y0: 0, x1: 10, y1: 2});
  assert.deepEqual(resize({x0: 2, y0: 2, x1: 6, y1: 4}, "se", 8, 9), {x0: 2, y0: 2, x1: 8, y1: 9});
  assert.deepEqual(resize({x0: 2, y0: 2, x1: 6, y1: 4}, "w", 9, 0), {x0: 6, y0: 2, x1: 9, y1: 4});  // flipped
  assert.equal(handleAt({x0: 0, y0: 0, x1: 10, y1: 10}, 10.5, 5, 1), "e");
  assert.equal(handleAt({x0: 0, y0: 0, x1: 10, y1: 10}, 5, 5, 1), null);
});

test("snap moves edges to neighbours and reports guides", () => {
  const others = [{x0: 20, y0: 0, x1: 30, y1: 10}];
  const {rect, guides} = snap({x0: 0, y0: 3, x1: 18, y1: 8}, others, 3, ["x1"]);
  assert.deepEqual(rect, {x0: 0, y0: 3, x1: 20, y1: 8});
  assert.deepEqual(guides, [{axis: "x", at: 20}]);
  // a drag moves both edges: the size is kept
  const drag = snap({x0: 31, y0: 1, x1: 35, y1: 9}, others, 2);
  assert.deepEqual(drag.rect, {x0: 30, y0: 0, x1: 34, y1: 8});
  assert.equal(drag.guides.length, 2);
  assert.deepEqual(snap({x0: 0, y0: 0, x1: 5, y1: 5}, others, 2, ["x1"]).guides, []);
  assert.deepEqual(snap({x0: 1, y0: 0, x1: 5, y1: 5}, [], 2, ["x0"], {width: 50, height: 50}).rect.x0, 0);
});

test("repeat on a row, a column and a grid", () => {
  const r = {x0: 0, y0: 0, x1: 4, y1: 6};
  assert.equal(repeatRect(r, {cols: 5, dx: 10}).length, 5);
  assert.deepEqual(repeatRect(r, {rows: 3, dy: 8})[2], {x0: 0, y0: 16, x1: 4, y1: 22});
  const grid = repeatRect(r, {cols: 3, rows: 2, dx: 10, dy: 20});
  assert.equal(grid.length, 6);
  assert.deepEqual(grid[5], {x0: 20, y0: 20, x1: 24, y1: 26});
  assert.throws(() => repeatRect(r, {cols: 0}), /at least 1/);
  assert.throws(() => repeatRect(r, {cols: 100, rows: 100}), /2000/);
});

test("homography maps the four corners and is projective in between", async () => {
  const {applyHomography, homography, isConvexQuad, rectifiedSize} = await import("../editor/geometry.js");
  const src = [[10, 20], [110, 10], [120, 90], [5, 100]];
  const dst = [[0, 0], [100, 0], [100, 80], [0, 80]];
  const h = homography(dst, src);  // output -> source, as the preview samples
  for (let i = 0; i < 4; i++) {
    const [x, y] = applyHomography(h, ...dst[i]);
    assert.ok(Math.abs(x - src[i][0]) < 1e-6 && Math.abs(y - src[i][1]) < 1e-6);
  }
  const id = homography(dst, dst);
  assert.deepEqual(applyHomography(id, 37, 12).map((v) => Math.round(v * 1e6) / 1e6), [37, 12]);
  assert.deepEqual(rectifiedSize([[0, 0], [100, 0], [100, 50], [0, 50]]), [100, 50]);
  assert.equal(isConvexQuad(src), true);
  assert.equal(isConvexQuad([[0, 0], [10, 0], [0, 10], [10, 10]]), false);  // crossed
  assert.throws(() => homography([[0, 0], [0, 0], [0, 0], [0, 0]], dst), /homography/);
});

test("identical: rectangles drawn twice, by box and class", () => {
  const wall = {label: "facade", x0: 0, y0: 0, x1: 10, y1: 10};
  assert.deepEqual(identical([wall, {...wall}, {...wall, label: "window"}, {...wall, x1: 9}]),
    [{label: "facade", count: 2}]);
  assert.deepEqual(identical([wall]), []);
});

test("boxes of the photo as taken are carried through its rectification; those outside the facade are left out", () => {
  // the facade seen from the left: its right edge shorter in the photo; rectified to 300 x 200
  const corners = [[100, 50], [400, 100], [400, 300], [100, 350]];
  const rects = [{label: "window", x0: 100, y0: 50, x1: 130, y1: 80},  // at the facade's top-left corner
    {label: "door", x0: 370, y0: 250, x1: 400, y1: 300},  // at its bottom-right corner
    {label: "window", x0: 0, y0: 0, x1: 60, y1: 40}];  // beside it, off the facade
  const {rects: out, left} = throughRectification(rects, corners, 300, 200);
  assert.equal(left, 1);
  assert.deepEqual(out[0].label, "window");
  assert.equal(out[0].x0, 0);
  assert.equal(out[0].y0, 0);
  assert.ok(out[0].x1 > 20 && out[0].x1 < 40 && out[0].y1 > 10 && out[0].y1 < 30, JSON.stringify(out[0]));
  assert.equal(out[1].x1, 300);
  assert.equal(out[1].y1, 200);
  // an identity rectification keeps every box as it is
  const same = throughRectification(rects.slice(0, 2), [[0, 0], [500, 0], [500, 400], [0, 400]], 500, 400);
  assert.deepEqual(same.rects.map(({x0, y0, x1, y1}) => [x0, y0, x1, y1]), [[100, 50, 130, 80], [370, 250, 400, 300]]);
});
