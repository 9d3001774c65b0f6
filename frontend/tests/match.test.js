import assert from "node:assert/strict";
import {test} from "node:test";

import {findSimilar, toGray} from "../editor/match.js";

function facade(width, height, windows) {
  const data = new Uint8ClampedArray(width * height * 4).fill(200);
  for (const w of windows) {
    for (let y = w.y0; y < w.y1; y++) {
      for (let x = w.x0; x < w.x1; x++) {
        const i = 4 * (y * width + x);
        const frame = x === w.x0 || y === w.y0 || x === w.x1 - 1 || y === w.y1 - 1;
        data[i] = data[i + 1] = data[i + 2] = frame ? 30 : 90;
      }
    }
  }
  return {width, height, data};
}

test("finds the other windows of a row, not the drawn one, not overlapping", () => {
  const windows = [0, 1, 2, 3].map((i) => ({x0: 10 + 30 * i, y0: 20, x1: 26 + 30 * i, y1: 44}));
  const gray = toGray(facade(140, 80, windows));
  const found = findSimilar(gray, windows[0], {threshold: 0.9});
  assert.equal(found.length, 3);
  const xs = found.map((f) => f.x0).sort((a, b) => a - b);
  assert.deepEqual(xs, [40, 70, 100]);
  assert.ok(found.every((f) => f.y0 === 20 && f.score > 0.9));
  assert.equal(findSimilar(gray, windows[0], {threshold: 0.9, exclude: [windows[1]]}).length, 2);
});

test("a flat or tiny template finds nothing", () => {
  const gray = toGray(facade(60, 40, []));
  assert.deepEqual(findSimilar(gray, {x0: 5, y0: 5, x1: 20, y1: 20}), []);
  assert.deepEqual(findSimilar(gray, {x0: 5, y0: 5, x1: 6, y1: 6}), []);
});
