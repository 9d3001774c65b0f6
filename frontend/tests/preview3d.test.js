import assert from "node:assert/strict";
import {test} from "node:test";

import {elementOf, elementsUnder, elementText, fitView, keyLight, VIEW_DIRECTION} from "../procedure/preview3d-view.js";

const facade = {min: [0, 0, -0.15], max: [12, 18, 0.5]};  // metres: a wall with windows behind, balconies before

function corners(box) {
  const out = [];
  for (const x of [box.min[0], box.max[0]]) for (const y of [box.min[1], box.max[1]]) {
    for (const z of [box.min[2], box.max[2]]) out.push([x, y, z]);
  }
  return out;
}

// where a point lands on the screen of a camera at `position` looking at `target` (normalized device coordinates)
function project(p, position, target, fovDeg, aspect) {
  const sub = (a, b) => a.map((v, i) => v - b[i]);
  const dot = (a, b) => a.reduce((s, v, i) => s + v * b[i], 0);
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const norm = (a) => a.map((v) => v / Math.hypot(...a));
  const back = norm(sub(position, target));
  const right = norm(cross([0, 1, 0], back));
  const up = cross(back, right);
  const d = sub(p, position);
  const depth = -dot(d, back);
  const t = Math.tan((fovDeg * Math.PI) / 360);
  return [dot(d, right) / (depth * t * aspect), dot(d, up) / (depth * t), depth];
}

test("fit to view looks at the centre and keeps every corner on the screen, tightly", () => {
  for (const aspect of [0.5, 1, 16 / 9, 3]) {
    const v = fitView(facade, 35, aspect);
    assert.deepEqual(v.target, [6, 9, 0.175]);
    const screen = corners(facade).map((c) => project(c, v.position, v.target, 35, aspect));
    for (const [x, y, depth] of screen) {
      assert.ok(Math.abs(x) <= 1 / 1.1 + 1e-9 && Math.abs(y) <= 1 / 1.1 + 1e-9, `${x} ${y} at aspect ${aspect}`);
      assert.ok(depth > v.near && depth < v.far);
    }
    // one corner touches the margin: no closer camera would show it all
    const widest = Math.max(...screen.map(([x, y]) => Math.max(Math.abs(x), Math.abs(y))));
    assert.ok(Math.abs(widest - 1 / 1.1) < 1e-9, String(widest));
  }
  const v = fitView(facade, 35, 1);
  const along = v.position.map((p, i) => p - v.target[i]);
  const n = Math.hypot(...VIEW_DIRECTION);
  along.forEach((c, i) => assert.ok(Math.abs(c / v.distance - VIEW_DIRECTION[i] / n) < 1e-9));
  // straight from the front, a wall twice as tall as wide fills the height of a square view
  const front = fitView({min: [0, 0, 0], max: [1, 2, 0]}, 90, 1, {direction: [0, 0, 1], margin: 1});
  front.position.forEach((c, i) => assert.ok(Math.abs(c - [0.5, 1, 1][i]) < 1e-12, String(front.position)));
});

test("the key light rakes from the upper left in front, its shadow covering the facade", () => {
  const k = keyLight(facade);
  const from = k.position.map((p, i) => p - k.target[i]);
  assert.ok(from[0] < 0 && from[1] > 0 && from[2] > 0);
  const distance = Math.hypot(...from);
  for (const c of corners(facade)) {
    const d = c.map((v, i) => v - k.target[i]);
    assert.ok(Math.hypot(...d) <= k.shadowHalf);  // within the shadow camera whichever way it is turned
    const depth = distance - d.reduce((s, v, i) => s + v * from[i], 0) / distance;
    assert.ok(depth > k.near && depth < k.far);
  }
});

test("an element is the nearest object carrying a label and a tree path", () => {
  const root = {userData: {facaid: {units: "metres"}}, children: []};
  const wall = {userData: {label: "facade", path: "root", box_px: [0, 0, 400, 600]}, parent: root, children: []};
  const window2 = {userData: {label: "window", path: "root/1/0/2"}, parent: root, children: []};
  const front = {userData: {}, parent: window2, children: []};  // a primitive of the element's mesh (with the photo)
  window2.children.push(front, {userData: {}, parent: window2, children: []});
  root.children.push(wall, window2);
  assert.equal(elementOf(front), window2);
  assert.equal(elementOf(wall), wall);
  assert.equal(elementOf(root), null);
  assert.deepEqual(elementsUnder(root), [wall, window2]);
  assert.equal(elementText(wall), "facade · root · x 0–400, y 0–600 px");
  assert.equal(elementText(window2), "window · root/1/0/2");
});
